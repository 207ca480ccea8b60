"""Snakemake script: a run's parts, from its own files: its part of each flight's rerun
recording, and its parts of the sweep, per-flight, records, and (for a run scored on
the injected grid) detectability and isolation tables, which their rules merge."""

import logging
from pathlib import Path

from alfa_bench.analysis.detectability import detectability_table
from alfa_bench.analysis.isolation import isolation_rows
from alfa_bench.analysis.per_flight import per_flight_rows
from alfa_bench.analysis.sweep import sweep_table
from alfa_bench.data import read_manifest
from alfa_bench.outputs.parquet import record_rows
from alfa_bench.outputs.parts import write_part, write_part_rows
from alfa_bench.outputs.provenance import read_provenance
from alfa_bench.outputs.records import iter_records, read_records
from alfa_bench.outputs.rerun_log import write_run_part
from alfa_bench.outputs.traces import read_trace, read_traces
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
method = sm.wildcards.method
out = Path(sm.output.recordings)
out.mkdir(parents=True, exist_ok=True)
for flight in manifest.loc[manifest["ground_truth"], "flight"]:
    # a flight the run excluded has no trace, and no part: the recording is without it
    trace = Path(sm.input.traces) / f"{flight}.npz"
    if trace.exists():
        write_run_part(flight, method, read_trace(trace), out / f"{flight}.rrd",
                       read_provenance(trace))
logging.info("%s: recordings written", method)

records = read_records([sm.input.detections])
traces = read_traces([sm.input.traces], probes=False)
deadline = float(sm.params.deadline_s)
write_part(sweep_table(records, traces, manifest, sm.params.subsets, deadline), sm.output.sweep)
write_part_rows(per_flight_rows(records, traces, manifest, deadline), sm.output.per_flight)
write_part_rows(record_rows(records), sm.output.records)
if "injected" in sm.input.keys():
    injected = read_manifest(sm.input.injected_manifest)
    write_part(detectability_table(iter_records([sm.input.injected]), injected, records),
               sm.output.detectability)
    write_part(isolation_rows(iter_records([sm.input.injected]), "sensor"),
               sm.output.isolation_sensors)
    write_part(isolation_rows(records, "actuator"), sm.output.isolation_actuators)
logging.info("%s: parts written", method)
