# Each run's parts of what every run's results make up, from that run's files alone, so
# that a changed run re-runs its own job and the merges, not every run's work: its part
# of each flight's rerun recording, and of the tables whose work is per run (sweep,
# per-flight, records; for a run scored on the injected grid, detectability and both
# isolation matrices). The merges are those tables' rules. One job per run: a job's
# start (Python, pandas, rerun: about a second) costs more than a run's work in any
# one part, and on one machine the jobs fork from a server that imported them once
# (workflow/parts_job.py).
rule run_parts_reference:
    input:
        manifest="results/flights.csv",
        detections="results/detections/{method}",
        traces="results/traces/{method}",
        code=module_sources("alfa_bench.workflow.parts_job"),
    output:
        recordings=directory("results/rerun/{method}"),
        sweep="results/parts/sweep/{method}.csv",
        per_flight="results/parts/per_flight/{method}.jsonl",
        records="results/parts/records/{method}.jsonl",
    params:
        subsets=json.dumps(SUBSETS),
        deadline_s=config["scoring"]["deadline_s"],
        injected="",
    resources:
        **JOB_RESOURCES,
    log:
        "results/logs/run_parts/{method}.log",
    benchmark:
        "results/benchmarks/run_parts/{method}.tsv"
    wildcard_constraints:
        method="|".join(REFERENCES),
    shell:
        PARTS_JOB


use rule run_parts_reference as run_parts with:
    input:
        manifest="results/flights.csv",
        detections="results/detections/{method}",
        traces="results/traces/{method}",
        injected_manifest="results/injected/flights.csv",
        injected="results/injected/detections/{method}",
        code=module_sources("alfa_bench.workflow.parts_job"),
    output:
        recordings=directory("results/rerun/{method}"),
        sweep="results/parts/sweep/{method}.csv",
        per_flight="results/parts/per_flight/{method}.jsonl",
        records="results/parts/records/{method}.jsonl",
        detectability="results/parts/detectability/{method}.csv",
        isolation_sensors="results/parts/isolation_sensors/{method}.csv",
        isolation_actuators="results/parts/isolation_actuators/{method}.csv",
    params:
        subsets=json.dumps(SUBSETS),
        deadline_s=config["scoring"]["deadline_s"],
        injected=lambda w, input, output: " ".join(
            f"--{k.replace('_', '-')} {shlex.quote(v)}" for k, v in [
                ("injected_manifest", input.injected_manifest), ("injected", input.injected),
                ("detectability", output.detectability),
                ("isolation_sensors", output.isolation_sensors),
                ("isolation_actuators", output.isolation_actuators)]),
    wildcard_constraints:
        method="|".join(DETECTORS),
