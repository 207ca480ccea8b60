if DOWNLOAD:

    # a failed download ends the run on what to do: its message last, the details in
    # its log (Snakemake's own lines come before)
    onerror:
        _log = Path("results/logs/download_alfa.log")
        if _log.exists() and "download failed: " in _log.read_text():
            _why = _log.read_text().split("download failed: ", 1)[1].split("\n", 1)[0]
            print(f"\nThe ALFA download failed: {_why}\nDetails: {_log}", file=sys.stderr)

    rule download_alfa:
        output:
            directory(PROCESSED),
        params:
            download=config["download"],
        log:
            "results/logs/download_alfa.log",
        script:
            "../scripts/download_alfa.py"


rule manifest:
    input:
        processed=PROCESSED,
    output:
        manifest="results/flights.csv",
        failures="results/load_failures.csv",
        # every flight parsed once: what every later job reads (data/cache.py)
        cache=directory("results/cache"),
    params:
        strict=config["strict"],
    log:
        "results/logs/manifest.log",
    benchmark:
        "results/benchmarks/manifest.tsv"
    script:
        "../scripts/manifest.py"
