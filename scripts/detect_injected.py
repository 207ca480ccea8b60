"""Snakemake script: one configured method on the injected flights, built in memory
from the cached fault-free flights, and calibrated on the real flights only."""

import json
from pathlib import Path

from alfa_bench.analysis.detections import write_detections
from alfa_bench.analysis.logs import log_to
from alfa_bench.data import AlfaDataError, load_cached, read_manifest
from alfa_bench.data.inject import injected_flights
from alfa_bench.methods import REGISTRY

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest, real = read_manifest(sm.input.manifest), read_manifest(sm.input.calibrate_on)
grid = sm.params.injection
spec = json.loads(sm.params.spec)
calibrated = REGISTRY[spec["detector"]].calibrated     # fitted on the real flights only
free = real.loc[real["fault_class"] == "none", "flight"]
loaded = load_cached(sm.input.cache, real, None if calibrated else free)
built, _ = injected_flights({name: loaded[name] for name in free}, real,
                            sm.params.processed, grid["sensors"], grid["faults"],
                            grid["onsets"])
sha = dict(zip(manifest["flight"], manifest["sha256"], strict=True))
if {name: s for name, (_, s) in built.items()} != sha:
    raise AlfaDataError(f"{sm.input.manifest} is not the grid the config and the cached "
                        "flights give: re-run the inject rule")
flights = {name: flight for name, (flight, _) in built.items()}
if calibrated:
    flights |= loaded
write_detections(sm.wildcards.method, spec, flights, manifest,
                 dict(sm.params.calibration), strict=sm.params.strict, config=sm.config,
                 out=Path(sm.output.detections), traces=None, calibrate_on=real,
                 probes=False)    # the records hold all that is read of these runs
