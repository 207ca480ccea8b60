"""Snakemake script: the run's provenance, with the SHA-256 of every output."""

from alfa_bench.analysis.logs import log_to
from alfa_bench.analysis.provenance import run_provenance, write_run_file
from alfa_bench.data import read_manifest

sm = snakemake  # noqa: F821
log_to(sm.log[0])
write_run_file(sm.output[0], run_provenance(sm.config, read_manifest(sm.input.manifest)),
               [*sm.input, "results/load_failures.csv"],
               unchecked=sm.params.unchecked)
