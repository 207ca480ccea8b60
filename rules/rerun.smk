rule rerun_logs:
    # the longest jobs start first, and the short ones fill the other cores
    priority: 2
    input:
        manifest="results/flights.csv",
        cache="results/cache",
        traces=expand("results/traces/{method}", method=METHODS),
        code=script_code("rerun_logs"),
    output:
        directory("results/rerun"),
    params:
        # canonical JSON: reordered keys are not a change (the tab order follows input)
        methods=json.dumps(config["methods"], sort_keys=True),
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/rerun_logs.log",
    benchmark:
        "results/benchmarks/rerun_logs.tsv"
    script:
        "../scripts/rerun_logs.py"


# The README's picture of a recording in rerun's web viewer, taken in headless Chromium
# (workflow/viewer.py). Refreshed by this explicit target, never by `all`: it writes a
# tracked file, and needs Chromium.
rule viewer_screenshot:
    input:
        "results/rerun",
        code=script_code("viewer_screenshot"),
    output:
        "docs/viewer.png",
    params:
        flight=config["figures"].get("viewer_flight", ""),
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/viewer_screenshot.log",
    script:
        "../scripts/viewer_screenshot.py"
