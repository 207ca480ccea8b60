# a failed download, or a folder without a flight that reads, ends the run on what to do:
# its message last, the details in its log (Snakemake's own lines come before)
onerror:
    forkserver.stop(SERVER_ENV)
    forkserver.stop(PARTS_SERVER_ENV)
    forkserver.stop(SCRIPT_SERVER_ENV)
    if _last := failure_message(ALFA_SOURCE, ALFA_DIR):
        print(f"\n{_last}", file=sys.stderr)


if DOWNLOAD:

    rule download_alfa:
        output:
            directory(PROCESSED),
        params:
            download=config["download"],
        resources:
            **JOB_RESOURCES,
        log:
            "results/logs/download_alfa.log",
        script:
            "../scripts/download_alfa.py"


rule manifest:
    input:
        processed=PROCESSED,
        code=script_code("manifest"),
        # a corpus's logs left out at conversion: failures like a flight that does not load
        left_out=[CONVERTED / "left_out.csv"] if CORPUS else [],
    output:
        manifest="results/flights.csv",
        failures="results/load_failures.csv",
        # every flight parsed once: what every later job reads (data/cache.py)
        cache=directory("results/cache"),
    params:
        strict=config["strict"],
        # the signals the data checks read: a corpus's own, else the whole catalogue
        signals=[s for s, why in read_signals(CONVERTED).items() if why is None] if CORPUS else None,
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/manifest.log",
    benchmark:
        "results/benchmarks/manifest.tsv"
    script:
        "../scripts/manifest.py"
