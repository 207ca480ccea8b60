"""Snakemake script: run one configured method over every flight with ground truth and,
for a method scored on it, over the injected sensor-fault grid, built in memory from
the cached fault-free flights; each fold is fitted once, on real flights only. Writes
the detection records, traces, the method's part of each flight's rerun recording and
of its figure, and the flights the method had to exclude."""

import json
from collections import ChainMap
from pathlib import Path

from alfa_bench.data import AlfaDataError, load_cached, read_manifest
from alfa_bench.data.inject import InjectedGrid
from alfa_bench.outputs.records import write_detections
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
flights = load_cached(sm.input.cache, manifest)
injected = None
if "injected" in sm.output.keys():
    grid, on_grid = sm.params.injection, read_manifest(sm.input.injected)
    free = manifest.loc[manifest["fault_class"] == "none", "flight"]
    built = InjectedGrid({name: flights[name] for name in free}, manifest,
                         sm.params.processed, grid["sensors"], grid["faults"], grid["onsets"])
    if built.sha256 != dict(zip(on_grid["flight"], on_grid["sha256"], strict=True)):
        raise AlfaDataError(f"{sm.input.injected} is not the grid the config and the "
                            "cached flights give: re-run the inject rule")
    flights = ChainMap(flights, built)       # each injected flight built when scored
    injected = on_grid, Path(sm.output.injected)
write_detections(sm.wildcards.method, json.loads(sm.params.spec), flights, manifest,
                 dict(sm.params.calibration), strict=sm.params.strict, config=sm.config,
                 out=Path(sm.output.detections), traces=Path(sm.output.traces),
                 recordings=Path(sm.output.recordings), panels=Path(sm.output.panels),
                 injected=injected)
