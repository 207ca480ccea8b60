"""Snakemake script: the grid of injected sensor faults, and its manifest."""

import logging
from pathlib import Path

from alfa_bench.analysis.logs import log_to
from alfa_bench.data import build_manifest, read_manifest
from alfa_bench.data.inject import inject_grid

sm = snakemake  # noqa: F821
log_to(sm.log[0])
grid = sm.params.injection
flights = inject_grid(Path(sm.input.processed), read_manifest(sm.input.manifest),
                      Path(sm.output.processed), grid["sensors"], grid["faults"],
                      grid["onsets"])
logging.info("%d injected flights", len(flights))
build_manifest(sm.output.processed).to_csv(sm.output.manifest, index=False)
