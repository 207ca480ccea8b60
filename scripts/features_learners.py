"""Snakemake script: the generic learners on raw windows and on physical residuals."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.features_learners import (
    chosen_configurations,
    features_learners,
    features_learners_markdown,
    features_learners_sections,
)
from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import read_manifest
from alfa_bench.outputs.provenance import read_table, stamp
from alfa_bench.outputs.records import read_records
from alfa_bench.render import latex_tables
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
chosen = {Path(folder).name: chosen_configurations(read_records([folder]))
          for folder in sm.input.nested}
table = features_learners(read_table(sm.input.per_flight), read_table(sm.input.comparison),
                          manifest, list(sm.params.rows), sm.params.primary,
                          float(sm.params.stable), chosen, read_table(sm.input.left_out))
table.to_csv(sm.output.csv, index=False)
Path(sm.output.md).write_text(features_learners_markdown(table, sm.params.primary,
                                                         float(sm.params.deadline_s)))
Path(sm.output.tex).write_text(latex_tables(features_learners_sections(table),
                                            "features-learners") if len(table) else "")
prov = run_provenance(sm.config, manifest)
for path in (sm.output.csv, sm.output.md, sm.output.tex):
    stamp(path, prov)
