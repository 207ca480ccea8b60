"""Snakemake script: the walk from a public study's protocol to this project's."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.analysis.public_study import protocol_steps, protocol_steps_markdown
from alfa_bench.data import read_manifest
from alfa_bench.outputs.provenance import read_table, stamp
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
table = protocol_steps(read_table(sm.input.per_flight), manifest, list(sm.params.steps),
                       sm.params.primary, float(sm.params.stable))
table.to_csv(sm.output.csv, index=False)
Path(sm.output.md).write_text(protocol_steps_markdown(table, sm.params.primary,
                                                      float(sm.params.deadline_s)))
prov = run_provenance(sm.config, manifest)
for path in (sm.output.csv, sm.output.md):
    stamp(path, prov)
