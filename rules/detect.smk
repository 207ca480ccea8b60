import json


# The reference rows (role: reference) on the real flights only: they speak of ALFA's
# metric and emulation, not of sensors.
rule detect_reference:
    input:
        manifest="results/flights.csv",
        cache="results/cache",
        code=lambda w: detector_code(w.method),
    output:
        detections=directory("results/detections/{method}"),
        traces=directory("results/traces/{method}"),
        # the method's part of each flight's recording and figure, which rerun_logs
        # and flight_figures put together
        recordings=directory("results/rerun_parts/{method}"),
        panels=directory("results/figure_parts/{method}"),
    params:
        # canonical JSON, so that only a changed value (not a reordered key) re-runs it
        spec=lambda w: json.dumps(config["methods"][w.method], sort_keys=True),
        calibration=config["calibration"],
        stability=config["stability"],
        strict=config["strict"],
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/detect/{method}.log",
    benchmark:
        "results/benchmarks/detect/{method}.tsv"
    wildcard_constraints:
        method="|".join(REFERENCES),
    script:
        "../scripts/detect.py"


# Every other run, on the real flights and on the injected sensor-fault grid in one job
# (one fit per fold for both): a changed method re-runs only its own job.
use rule detect_reference as detect with:
    input:
        manifest="results/flights.csv",
        cache="results/cache",
        code=lambda w: detector_code(w.method),
        injected="results/injected/flights.csv",
    output:
        detections=directory("results/detections/{method}"),
        traces=directory("results/traces/{method}"),
        recordings=directory("results/rerun_parts/{method}"),
        panels=directory("results/figure_parts/{method}"),
        injected=directory("results/injected/detections/{method}"),
    params:
        spec=lambda w: json.dumps(config["methods"][w.method], sort_keys=True),
        calibration=config["calibration"],
        stability=config["stability"],
        strict=config["strict"],
        injection=config["injection"],
        processed=INJECTED_PROCESSED,
    wildcard_constraints:
        method="|".join(DETECTORS),
