# The injected sensor-fault grid (data/inject.py): built from the fault-free flights,
# scored by the detect jobs (rules/detect.smk), calibrated on the real flights only.


rule inject:
    input:
        manifest="results/flights.csv",
        cache="results/cache",
        code=script_code("inject"),
    output:
        manifest="results/injected/flights.csv",
        # flight-sensor pairs left out: the sensor's topic is missing or not measured
        skipped="results/injected/skipped.csv",
    params:
        injection=config["injection"],
        processed=INJECTED_PROCESSED,
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/inject.log",
    benchmark:
        "results/benchmarks/inject.tsv"
    script:
        "../scripts/inject.py"


# ALFA-format CSV copies of the injected flights, for use outside the pipeline; never
# part of `all` (the workflow builds them in memory): `snakemake injected_csv`
rule injected_csv:
    input:
        manifest="results/flights.csv",
        processed=PROCESSED,
        code=script_code("injected_csv"),
    output:
        processed=directory(INJECTED_PROCESSED),
    params:
        injection=config["injection"],
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/injected_csv.log",
    script:
        "../scripts/injected_csv.py"


# every run's rows, from its part (rules/parts.smk)
rule detectability:
    input:
        manifest="results/injected/flights.csv",
        calibrate_on="results/flights.csv",
        parts=expand("results/parts/detectability/{method}.csv", method=DETECTORS),
        code=script_code("detectability"),
    output:
        csv=report("results/tables/detectability.csv",
                   caption="../report/detectability_table.rst", category="Sensor faults"),
        md="results/tables/detectability.md",
        figure=report("results/figures/detectability.png",
                      caption="../report/detectability.rst", category="Sensor faults"),
    params:
        methods=DETECTORS,
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/detectability.log",
    benchmark:
        "results/benchmarks/detectability.tsv"
    script:
        "../scripts/detectability.py"


# every run's rows, from its parts (rules/parts.smk)
rule isolation:
    input:
        manifest="results/flights.csv",
        injected="results/injected/flights.csv",
        sensors=expand("results/parts/isolation_sensors/{method}.csv", method=DETECTORS),
        actuators=expand("results/parts/isolation_actuators/{method}.csv", method=DETECTORS),
        code=script_code("isolation"),
    output:
        sensors_csv="results/tables/isolation_sensors.csv",
        sensors_md=report("results/tables/isolation_sensors.md",
                          caption="../report/sensor_faults.rst", category="Sensor faults"),
        actuators_csv="results/tables/isolation_actuators.csv",
        actuators_md=report("results/tables/isolation_actuators.md",
                            caption="../report/isolation_actuators.rst", category="Comparison"),
    params:
        methods=DETECTORS,
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/isolation.log",
    benchmark:
        "results/benchmarks/isolation.tsv"
    script:
        "../scripts/isolation.py"
