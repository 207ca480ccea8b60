# Each run's parts of what every run's results make up, from that run's files alone, so
# that a changed run re-runs its own job and the merges, not every run's work: its part
# of each flight's rerun recording. One job per run: a job's start (Python, pandas,
# rerun) costs more than a run's work in any one part.
rule run_parts:
    input:
        manifest="results/flights.csv",
        traces="results/traces/{method}",
        code=script_code("run_parts"),
    output:
        recordings=directory("results/rerun/{method}"),
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/run_parts/{method}.log",
    benchmark:
        "results/benchmarks/run_parts/{method}.tsv"
    script:
        "../scripts/run_parts.py"
