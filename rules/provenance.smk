# The run's provenance once, with every output's SHA-256: the tables stay plain files
rule provenance:
    input:
        [f for f in rules.all.input if f != RUN_FILE],
        manifest="results/flights.csv",
        detections=expand("results/detections/{method}", method=METHODS),
        traces=expand("results/traces/{method}", method=METHODS),
        injected=expand("results/injected/detections/{method}", method=DETECTORS),
        grid=rules.inject.output,
        code=script_code("provenance"),
    output:
        RUN_FILE,
    params:
        # differ between runs by nature: rerun's clock-drawn ids, measured times
        unchecked=["results/rerun/*/*.rrd", "results/runtime/*"],
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/provenance.log",
    benchmark:
        "results/benchmarks/provenance.tsv"
    script:
        "../scripts/provenance.py"
