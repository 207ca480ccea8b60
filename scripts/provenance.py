"""Snakemake script: the run's provenance, with the SHA-256 of every output."""

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import read_manifest
from alfa_bench.outputs.provenance import write_run_file
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
write_run_file(sm.output[0], run_provenance(sm.config, read_manifest(sm.input.manifest)),
               [*sm.input, "results/load_failures.csv"],
               unchecked=sm.params.unchecked)
