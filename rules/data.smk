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
        PROCESSED,
    output:
        "data/flights.csv",
    params:
        processed=str(PROCESSED),
    log:
        "results/logs/manifest.log",
    script:
        "../scripts/manifest.py"
