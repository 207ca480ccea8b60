"""Snakemake script: every configured method on the injected flights, in one job (reading
the flights costs more than scoring them), calibrated on the real flights only."""

import json
from pathlib import Path

from alfa_bench.analysis.detections import write_detections
from alfa_bench.analysis.logs import log_to
from alfa_bench.data import load_flight, read_manifest

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest, real = read_manifest(sm.input.manifest), read_manifest(sm.input.calibrate_on)
flights = {name: load_flight(Path(sm.input.processed) / name)
           for name in manifest.loc[manifest["ground_truth"], "flight"]}
flights |= {name: load_flight(Path(sm.input.real) / name)
            for name in real.loc[real["ground_truth"], "flight"]}
specs = json.loads(sm.params.methods)
for method in sm.params.order:
    write_detections(method, specs[method], flights, manifest, dict(sm.params.calibration),
                     strict=sm.params.strict, config=sm.config,
                     out=Path(sm.output.detections) / method,
                     traces=Path(sm.output.traces) / method, calibrate_on=real,
                     probes=False)    # isolation reads scores only
