# the run ends on a line naming the flights it could not score on, when there are any,
# and one naming the page to open; printed at exit, since Snakemake logs its own closing
# lines (the log's path, the time taken) after this block
onsuccess:
    forkserver.stop(SERVER_ENV)
    forkserver.stop(PARTS_SERVER_ENV)
    forkserver.stop(SCRIPT_SERVER_ENV)
    if _closing := closing_lines(PRIMARY):
        atexit.register(print, *_closing, sep="\n", file=sys.stderr, flush=True)


rule tables:
    input:
        manifest="results/flights.csv",
        load_failures="results/load_failures.csv",
        detections=expand("results/detections/{method}", method=METHODS),
        leakage="results/tables/leakage.csv",
        code=script_code("tables"),
    output:
        failures=report("results/tables/failures.csv", caption="../report/failures.rst",
                        category="Comparison"),
        # the flights off the common ground every run is ranked on, and why
        left_out="results/tables/left_out.csv",
        summary="results/tables/summary.csv",
        by_fault="results/tables/by_fault.csv",
        comparison=report("results/tables/comparison.csv", caption="../report/comparison.rst",
                          category="Comparison"),
        comparison_html=report("results/tables/comparison.html",
                               caption="../report/comparison.rst", category="Comparison"),
        summary_md="results/tables/summary.md",
        by_fault_md="results/tables/by_fault.md",
        comparison_md="results/tables/comparison.md",
        summary_tex="results/tables/summary.tex",
        by_fault_tex="results/tables/by_fault.tex",
        comparison_tex="results/tables/comparison.tex",
        # how much each outcome owes to the calibration flights (analysis/stability.py)
        stability="results/tables/stability.csv",
        stability_md=report("results/tables/stability.md", caption="../report/stability.rst",
                            category="Comparison"),
        calibration="results/tables/calibration.csv",
        # the runs a corpus of logs cannot run, with the signals it lacks (empty on ALFA)
        not_applicable="results/tables/not_applicable.csv",
    params:
        subsets=SUBSETS,
        primary=PRIMARY,
        deadline_s=config["scoring"]["deadline_s"],
        stability=config["stability"],
        not_applicable=config.get("not_applicable", {}),
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/tables.log",
    benchmark:
        "results/benchmarks/tables.tsv"
    script:
        "../scripts/tables.py"


# The page a reader opens first: the headline, the sweep, detections by class
rule index_page:
    input:
        manifest="results/flights.csv",
        comparison="results/tables/comparison.csv",
        by_fault="results/tables/by_fault.csv",
        left_out="results/tables/left_out.csv",
        ceiling="results/tables/ceiling.csv",
        sweep="results/figures/sweep.png",
        code=script_code("index_page"),
    output:
        "results/index.html",
    params:
        primary=PRIMARY,
        not_applicable=config.get("not_applicable", {}),
        # what the page says it ranks: ALFA's flights, or the corpus of logs given
        data=f"the logs of {CORPUS}" if CORPUS else "the ALFA flights",
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/index_page.log",
    script:
        "../scripts/index_page.py"


# The model fitted again on calibration pools, beside the thresholds alone; an explicit
# target (`snakemake stability_refit`), never part of `all`: a fit per pool and fold.
rule stability_refit:
    input:
        manifest="results/flights.csv",
        cache="results/cache",
        detections=expand("results/detections/{method}",
                          method=config["stability"]["refit"]["runs"]),
        code=script_code("stability_refit"),
    output:
        csv="results/tables/stability_refit.csv",
        md="results/tables/stability_refit.md",
    params:
        specs={m: config["methods"][m] for m in config["stability"]["refit"]["runs"]},
        calibration=config["calibration"],
        stability=config["stability"],
        subsets=SUBSETS,
        deadline_s=config["scoring"]["deadline_s"],
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/stability_refit.log",
    script:
        "../scripts/stability_refit.py"


# every run's rows, from its parts (rules/parts.smk)
rule per_flight:
    input:
        manifest="results/flights.csv",
        parts=expand("results/parts/per_flight/{method}.jsonl", method=METHODS),
        records=expand("results/parts/records/{method}.jsonl", method=METHODS),
        code=script_code("per_flight"),
    output:
        csv="results/tables/per_flight.csv",
        md="results/tables/per_flight.md",
        parquet="results/tables/per_flight.parquet",
        records="results/tables/detections.parquet",
        against_study="results/tables/against_study.csv",
    params:
        deadline_s=config["scoring"]["deadline_s"],
        study_run=config.get("public_study", {}).get("reproduction"),
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/per_flight.log",
    benchmark:
        "results/benchmarks/per_flight.tsv"
    script:
        "../scripts/per_flight.py"


# From a public study's protocol to this project's, one change at a time
rule protocol_steps:
    input:
        manifest="results/flights.csv",
        per_flight="results/tables/per_flight.csv",
        code=script_code("protocol_steps"),
    output:
        csv="results/tables/protocol_steps.csv",
        md="results/tables/protocol_steps.md",
    params:
        steps=config.get("public_study", {}).get("steps", []),
        primary=PRIMARY,
        deadline_s=config["scoring"]["deadline_s"],
        stable=config["stability"]["stable"],
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/protocol_steps.log",
    script:
        "../scripts/protocol_steps.py"


# The generic learners on raw windows (defaults, fair best) and on physical residuals
rule features_learners:
    input:
        manifest="results/flights.csv",
        per_flight="results/tables/per_flight.csv",
        comparison="results/tables/comparison.csv",
        # the flights off the common ground, which no cell counts
        left_out="results/tables/left_out.csv",
        # the nested runs' records, for the configuration each scored date chose
        nested=[f"results/detections/{row[key]}"
                for row in config.get("features_learners", [])
                for key in ("windows_best", "physical_best") if row.get(key) in METHODS],
        code=script_code("features_learners"),
    output:
        csv="results/tables/features_learners.csv",
        md="results/tables/features_learners.md",
        tex="results/tables/features_learners.tex",
    params:
        rows=config.get("features_learners", []),
        primary=PRIMARY,
        deadline_s=config["scoring"]["deadline_s"],
        stable=config["stability"]["stable"],
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/features_learners.log",
    script:
        "../scripts/features_learners.py"


rule runtime:
    input:
        manifest="results/flights.csv",
        detections=expand("results/detections/{method}", method=METHODS),
        injected=expand("results/injected/detections/{method}", method=DETECTORS),
        benchmarks=expand("results/benchmarks/detect/{method}.tsv", method=METHODS),
        code=script_code("runtime"),
    output:
        csv="results/runtime/runtime.csv",
        md="results/runtime/runtime.md",
        html=report("results/runtime/runtime.html", caption="../report/runtime.rst",
                    category="Runtime"),
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/runtime.log",
    benchmark:
        "results/benchmarks/runtime.tsv"
    script:
        "../scripts/runtime.py"


rule deadline:
    input:
        manifest="results/flights.csv",
        detections=expand("results/detections/{method}", method=METHODS),
        code=script_code("deadline"),
    output:
        csv="results/tables/deadline.csv",
        md=report("results/tables/deadline.md", caption="../report/deadline_table.rst",
                  category="Detection times"),
        figure=report("results/figures/deadline.png", caption="../report/deadline.rst",
                      category="Detection times"),
        detection_time=report("results/figures/detection_time.png",
                              caption="../report/detection_time.rst",
                              category="Detection times"),
    params:
        subsets=SUBSETS,
        deadlines_s=config["scoring"]["deadlines_s"],
        deadline_s=config["scoring"]["deadline_s"],
        subset=PRIMARY,
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/deadline.log",
    benchmark:
        "results/benchmarks/deadline.tsv"
    script:
        "../scripts/deadline.py"


# which signals carry the fault emulation, measured on the flights themselves
rule leakage:
    input:
        manifest="results/flights.csv",
        cache="results/cache",
        code=script_code("leakage"),
    output:
        csv="results/tables/leakage.csv",
        md="results/tables/leakage.md",
        html=report("results/tables/leakage.html", caption="../report/leakage.rst",
                    category="Leakage audit"),
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/leakage.log",
    benchmark:
        "results/benchmarks/leakage.tsv"
    script:
        "../scripts/leakage.py"


# what single physical features could reach per fault class, whatever the detector
rule ceiling:
    input:
        manifest="results/flights.csv",
        cache="results/cache",
        code=script_code("ceiling"),
    output:
        csv="results/tables/ceiling.csv",
        md="results/tables/ceiling.md",
        html=report("results/tables/ceiling.html", caption="../report/ceiling.rst",
                    category="Comparison"),
    params:
        subsets=SUBSETS,
        deadline_s=config["scoring"]["deadline_s"],
        margin_s=config["calibration"]["margin_s"],
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/ceiling.log",
    benchmark:
        "results/benchmarks/ceiling.tsv"
    script:
        "../scripts/ceiling.py"
