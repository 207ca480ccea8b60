if DOWNLOAD:

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
        manifest="data/flights.csv",
        failures="data/load_failures.csv",
        # every flight parsed once: what every later job reads (data/cache.py)
        cache=directory("results/cache"),
    params:
        strict=config["strict"],
    log:
        "results/logs/manifest.log",
    script:
        "../scripts/manifest.py"
