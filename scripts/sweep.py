"""Snakemake script: threshold sweeps of every method, merged from each run's part
(computed from its stored traces), as a table and a figure."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.analysis.sweep import merge_sweeps
from alfa_bench.data import read_manifest
from alfa_bench.outputs.figures import sweep_figure
from alfa_bench.outputs.parts import read_parts
from alfa_bench.outputs.provenance import stamp
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
sweep = merge_sweeps(read_parts(sm.input.parts), sm.params.subsets)
sweep.to_csv(sm.output.csv, index=False)
sweep_figure(sweep, sm.params.subset, sm.output.figure)
prov = run_provenance(sm.config, manifest)
for path in sm.output:
    stamp(path, prov)
