"""Snakemake script: ALFA-format CSV copies of the injected sensor-fault flights."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

import logging
from pathlib import Path

from alfa_bench.data import read_manifest
from alfa_bench.data.inject import inject_grid
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
grid = sm.params.injection
Path(sm.output.processed).mkdir(parents=True, exist_ok=True)
written, _ = inject_grid(Path(sm.input.processed), read_manifest(sm.input.manifest),
                         Path(sm.output.processed), grid["sensors"], grid["faults"],
                         grid["onsets"])
logging.info("%d injected flights written", len(written))
