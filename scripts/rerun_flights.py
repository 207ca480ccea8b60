"""Snakemake script: each flight's own part of its rerun recording (signals, fault,
layout); each run's part is written by its run_parts job."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

import logging
from pathlib import Path

from alfa_bench.analysis.provenance import provenance
from alfa_bench.data import read_cached, read_manifest
from alfa_bench.data.cache import cache_path
from alfa_bench.outputs.rerun_log import write_flight_part
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
runs, signals = list(sm.params.runs), list(sm.params.signals)
out = Path(sm.output[0])
for flight, sha in manifest.loc[manifest["ground_truth"], ["flight", "sha256"]].itertuples(
        index=False):
    # what the part is made of: the flight, and the runs and signals it lays out, not
    # their parameters (a run's part carries its own)
    prov = provenance({"runs": runs, "signals": signals}, {"flight_sha256": sha})
    write_flight_part(read_cached(cache_path(sm.input.cache, flight), sha), runs, signals,
                      out / f"{flight}.rrd", prov)
    logging.info("%s: written", flight)
