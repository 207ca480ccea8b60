"""Snakemake script: one rerun recording per flight, from every method's traces."""

import json
import logging
from pathlib import Path

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import read_cached, read_manifest
from alfa_bench.data.cache import cache_path
from alfa_bench.methods import make_detector
from alfa_bench.outputs.rerun_log import write_rerun_log
from alfa_bench.outputs.traces import read_trace
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
specs = json.loads(sm.params.methods)
detectors = [make_detector(spec["detector"], spec.get("params")) for spec in specs.values()]
signals = list(dict.fromkeys(s for d in detectors for s in d.signals()))
prov = run_provenance(sm.config, manifest)
sha = dict(zip(manifest["flight"], manifest["sha256"], strict=True))
out = Path(sm.output[0])
for flight in manifest.loc[manifest["ground_truth"], "flight"]:
    # a flight a method excluded has no trace of it, and is recorded without it
    traces = {Path(d).name: read_trace(p) for d in sm.input.traces
              if (p := Path(d) / f"{flight}.npz").exists()}
    write_rerun_log(read_cached(cache_path(sm.input.cache, flight), sha[flight]), traces,
                    signals, out / f"{flight}.rrd", prov)
    logging.info("%s: written", flight)
