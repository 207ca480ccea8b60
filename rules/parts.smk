# Each run's parts of what every run's results make up, from that run's files alone, so
# that a changed run re-runs its own job and the merges, not every run's work: its part
# of each flight's rerun recording, and of the tables whose work is per run (sweep,
# per-flight, records; for a run scored on the injected grid, detectability and both
# isolation matrices). The merges are those tables' rules. One job per run: a job's
# start (Python, pandas, rerun: about a second) costs more than a run's work in any
# one part.
rule run_parts_reference:
    input:
        manifest="results/flights.csv",
        detections="results/detections/{method}",
        traces="results/traces/{method}",
        code=script_code("run_parts"),
    output:
        recordings=directory("results/rerun/{method}"),
        sweep="results/parts/sweep/{method}.csv",
        per_flight="results/parts/per_flight/{method}.jsonl",
        records="results/parts/records/{method}.jsonl",
    params:
        subsets=SUBSETS,
        deadline_s=config["scoring"]["deadline_s"],
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/run_parts/{method}.log",
    benchmark:
        "results/benchmarks/run_parts/{method}.tsv"
    wildcard_constraints:
        method="|".join(REFERENCES),
    script:
        "../scripts/run_parts.py"


use rule run_parts_reference as run_parts with:
    input:
        manifest="results/flights.csv",
        detections="results/detections/{method}",
        traces="results/traces/{method}",
        injected_manifest="results/injected/flights.csv",
        injected="results/injected/detections/{method}",
        code=script_code("run_parts"),
    output:
        recordings=directory("results/rerun/{method}"),
        sweep="results/parts/sweep/{method}.csv",
        per_flight="results/parts/per_flight/{method}.jsonl",
        records="results/parts/records/{method}.jsonl",
        detectability="results/parts/detectability/{method}.csv",
        isolation_sensors="results/parts/isolation_sensors/{method}.csv",
        isolation_actuators="results/parts/isolation_actuators/{method}.csv",
    wildcard_constraints:
        method="|".join(DETECTORS),
