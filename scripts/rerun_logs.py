"""Snakemake script: one rerun recording per flight with every method's traces."""

import json
import logging
from pathlib import Path

from alfa_bench.analysis.logs import log_to
from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.analysis.rerun_log import write_rerun_log
from alfa_bench.analysis.traces import read_traces
from alfa_bench.data import read_cached, read_manifest
from alfa_bench.data.cache import cache_path
from alfa_bench.methods import make_detector

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
specs = json.loads(sm.params.methods)
order = [Path(d).name for d in sm.input.traces]
detectors = [make_detector(spec["detector"], spec.get("params")) for spec in specs.values()]
signals = list(dict.fromkeys(s for d in detectors for s in d.signals()))
traces = read_traces(sm.input.traces)
prov = run_provenance(sm.config, manifest)
sha = dict(zip(manifest["flight"], manifest["sha256"], strict=True))
out = Path(sm.output[0])
for flight in manifest.loc[manifest["ground_truth"], "flight"]:
    # a flight a method excluded is recorded without it
    mine = {m: traces[m, flight] for m in order if (m, flight) in traces}
    write_rerun_log(read_cached(cache_path(sm.input.cache, flight), sha[flight]), mine,
                    signals, out / f"{flight}.rrd", prov)
    logging.info("%s: written", flight)
