rule rerun_logs:
    input:
        manifest="data/flights.csv",
        traces=expand("results/traces/{method}", method=METHODS),
    output:
        directory("results/rerun"),
    params:
        # canonical JSON: reordered keys are not a change (the tab order follows input)
        methods=json.dumps(config["methods"], sort_keys=True),
        processed=str(PROCESSED),
    log:
        "results/logs/rerun_logs.log",
    script:
        "../scripts/rerun_logs.py"
