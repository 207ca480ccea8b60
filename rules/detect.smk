import json


rule detect:
    input:
        manifest="data/flights.csv",
        cache="results/cache",
        code=lambda w: detector_code(w.method),
    output:
        detections=directory("results/detections/{method}"),
        traces=directory("results/traces/{method}"),
    params:
        # canonical JSON, so that only a changed value (not a reordered key) re-runs it
        spec=lambda w: json.dumps(config["methods"][w.method], sort_keys=True),
        calibration=config["calibration"],
        strict=config["strict"],
    log:
        "results/logs/detect/{method}.log",
    benchmark:
        "results/benchmarks/detect/{method}.tsv"
    # before the injected jobs: the aggregates (sweep, figures, recordings) wait on these
    priority: 1
    script:
        "../scripts/detect.py"
