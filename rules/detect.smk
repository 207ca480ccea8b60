rule detect:
    input:
        manifest="data/flights.csv",
    output:
        directory("results/detections/{method}"),
    params:
        spec=lambda w: config["methods"][w.method],
        processed=str(PROCESSED),
        calibration=config["calibration"],
    log:
        "results/logs/detect/{method}.log",
    benchmark:
        "results/benchmarks/detect/{method}.tsv"
    script:
        "../scripts/detect.py"
