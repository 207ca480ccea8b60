"""Snakemake script: the detectability table and curves of the injected sensor faults,
merged from each run's part."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.detectability import detectability_markdown
from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import read_manifest
from alfa_bench.outputs.figures import detectability_figure
from alfa_bench.outputs.parts import read_parts
from alfa_bench.outputs.provenance import stamp
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
real = read_manifest(sm.input.calibrate_on)
table = read_parts(sm.input.parts)
table.to_csv(sm.output.csv, index=False)
Path(sm.output.md).write_text(detectability_markdown(table))
detectability_figure(table, sm.output.figure)
prov = run_provenance(sm.config, manifest, real)
for path in sm.output:
    stamp(path, prov)
