rule detect:
    input:
        manifest="data/flights.csv",
    output:
        detections=directory("results/detections/{method}"),
        traces=directory("results/traces/{method}"),
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
