# The rerun recordings, one file per flight and part, which the viewer opens as one
# recording per flight (`rerun results/rerun/*/<flight>.rrd`): each flight's own part
# here, each run's in run_parts, so that a changed run rewrites only its own files.
rule rerun_flights:
    input:
        manifest="results/flights.csv",
        cache="results/cache",
        code=script_code("rerun_flights"),
    output:
        # not a run's name (those start with a letter): the flights' own parts
        directory("results/rerun/_flight"),
    params:
        # the layout's tabs, one per run in config order, and the signals recorded
        runs=METHODS,
        signals=lambda w: recorded_signals(),
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/rerun_flights.log",
    benchmark:
        "results/benchmarks/rerun_flights.tsv"
    script:
        "../scripts/rerun_flights.py"


# The README's picture of a recording in rerun's web viewer, taken in headless Chromium
# (workflow/viewer.py). Refreshed by this explicit target, never by `all`: it writes a
# tracked file, and needs Chromium.
rule viewer_screenshot:
    input:
        flights="results/rerun/_flight",
        runs=expand("results/rerun/{method}", method=METHODS),
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
