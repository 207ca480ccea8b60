"""Snakemake script: results/index.html, the page a reader opens first."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import read_manifest
from alfa_bench.outputs.index_page import index_html
from alfa_bench.outputs.provenance import read_table, run_id
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
prov = run_provenance(sm.config, read_manifest(sm.input.manifest))
Path(sm.output[0]).write_text(index_html(
    read_table(sm.input.comparison), read_table(sm.input.by_fault), Path(sm.input.sweep),
    sm.params.primary, run_id(prov), read_table(sm.input.left_out),
    read_table(sm.input.ceiling), not_applicable=sm.params.not_applicable,
    data=sm.params.data))
