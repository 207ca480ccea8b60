"""Snakemake script: a run's parts, from its own files: its part of each flight's rerun
recording."""

import logging
from pathlib import Path

from alfa_bench.data import read_manifest
from alfa_bench.outputs.provenance import read_provenance
from alfa_bench.outputs.rerun_log import write_run_part
from alfa_bench.outputs.traces import read_trace
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
        logging.info("%s: written", flight)
