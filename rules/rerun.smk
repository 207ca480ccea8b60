rule rerun_logs:
    input:
        manifest="data/flights.csv",
        traces=expand("results/traces/{method}", method=METHODS),
    output:
        directory("results/rerun"),
    params:
        methods=config["methods"],
        processed=str(PROCESSED),
    log:
        "results/logs/rerun_logs.log",
    script:
        "../scripts/rerun_logs.py"
