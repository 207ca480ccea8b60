"""Snakemake script: run one configured method over every flight with ground truth;
write its detection records, traces, and the flights it had to exclude."""

import json
from pathlib import Path

from alfa_bench.analysis.detections import write_detections
from alfa_bench.analysis.logs import log_to
from alfa_bench.data import load_cached, read_manifest

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
flights = load_cached(sm.input.cache, manifest)
write_detections(sm.wildcards.method, json.loads(sm.params.spec), flights, manifest,
                 dict(sm.params.calibration), strict=sm.params.strict, config=sm.config,
                 out=Path(sm.output.detections), traces=Path(sm.output.traces))
