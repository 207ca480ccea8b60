"""Snakemake script: the run's provenance, with the SHA-256 of every output."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import read_manifest
from alfa_bench.outputs.provenance import write_run_file
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
# the outputs the run file lists, not the source files the rule takes as inputs too
code = set(sm.input.code)
write_run_file(sm.output[0], run_provenance(sm.config, read_manifest(sm.input.manifest)),
               [*(f for f in sm.input if f not in code),
                "results/load_failures.csv"],
               unchecked=sm.params.unchecked)
