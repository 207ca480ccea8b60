"""Snakemake script: the grid of injected sensor faults, and its manifest."""

import logging
from pathlib import Path

import pandas as pd

from alfa_bench.analysis.logs import log_to
from alfa_bench.analysis.provenance import run_provenance, stamp
from alfa_bench.data import build_manifest, read_manifest
from alfa_bench.data.inject import inject_grid

sm = snakemake  # noqa: F821
log_to(sm.log[0])
grid = sm.params.injection
manifest = read_manifest(sm.input.manifest)
# a corpus without fault-free flights gives an empty grid, not a missing folder
Path(sm.output.processed).mkdir(parents=True, exist_ok=True)
flights, skipped = inject_grid(Path(sm.input.processed), manifest,
                      Path(sm.output.processed), grid["sensors"], grid["faults"],
                      grid["onsets"])
logging.info("%d injected flights; %d flight-sensor pairs skipped", len(flights),
             len(skipped))
pd.DataFrame(skipped, columns=["flight", "sensor", "reason"]).to_csv(sm.output.skipped,
                                                                     index=False)
stamp(sm.output.skipped, run_provenance(sm.config, manifest))
build_manifest(sm.output.processed, allow_empty=True).to_csv(sm.output.manifest, index=False)
