# The injected sensor-fault grid (data/inject.py): built from the fault-free flights,
# scored by every method, calibrated on the real flights only.


rule inject:
    input:
        manifest="data/flights.csv",
        processed=PROCESSED,
    output:
        processed=directory("results/injected/processed"),
        manifest="results/injected/flights.csv",
        # flight-sensor pairs left out: the sensor's topic is missing or not measured
        skipped="results/injected/skipped.csv",
    params:
        injection=config["injection"],
    log:
        "results/logs/inject.log",
    script:
        "../scripts/inject.py"


rule detect_injected:
    input:
        manifest="results/injected/flights.csv",
        processed="results/injected/processed",
        calibrate_on="data/flights.csv",
        real=PROCESSED,
        code=sorted({f for m in DETECTORS for f in detector_code(m)}),
    output:
        detections=directory("results/injected/detections"),
        traces=directory("results/injected/traces"),
    params:
        # canonical JSON: a changed value re-runs this job, a reordered key does not
        methods=json.dumps({m: config["methods"][m] for m in DETECTORS}, sort_keys=True),
        order=DETECTORS,
        calibration=config["calibration"],
        strict=config["strict"],
    log:
        "results/logs/detect_injected.log",
    benchmark:
        "results/benchmarks/detect_injected.tsv"
    script:
        "../scripts/detect_injected.py"


rule detectability:
    input:
        manifest="results/injected/flights.csv",
        calibrate_on="data/flights.csv",
        detections="results/injected/detections",
        clean=expand("results/detections/{method}", method=DETECTORS),
    output:
        csv=report("results/tables/detectability.csv", category="Sensor faults"),
        md="results/tables/detectability.md",
        figure=report("results/figures/detectability.png",
                      caption="../report/detectability.rst", category="Sensor faults"),
    params:
        methods=DETECTORS,
    log:
        "results/logs/detectability.log",
    script:
        "../scripts/detectability.py"


rule isolation:
    input:
        manifest="data/flights.csv",
        injected="results/injected/flights.csv",
        detections=expand("results/detections/{method}", method=DETECTORS),
        traces=expand("results/traces/{method}", method=DETECTORS),
        injected_detections="results/injected/detections",
        injected_traces="results/injected/traces",
    output:
        sensors_csv="results/tables/isolation_sensors.csv",
        sensors_md=report("results/tables/isolation_sensors.md", category="Sensor faults"),
        actuators_csv="results/tables/isolation_actuators.csv",
        actuators_md=report("results/tables/isolation_actuators.md", category="Tables"),
    params:
        methods=DETECTORS,
    log:
        "results/logs/isolation.log",
    script:
        "../scripts/isolation.py"
