"""Snakemake script: every run's outcome and margins on every labelled flight, merged
from each run's part, and the public study's reproduction against its published
per-flight table."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

import pandas as pd

from alfa_bench.analysis.per_flight import per_flight_frame, per_flight_markdown
from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.analysis.public_study import against_study, against_study_markdown
from alfa_bench.data import read_manifest
from alfa_bench.outputs.parquet import write_parquet
from alfa_bench.outputs.parts import read_part_rows
from alfa_bench.outputs.provenance import stamp
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
deadline = float(sm.params.deadline_s)
table = per_flight_frame(read_part_rows(sm.input.parts))
table.to_csv(sm.output.csv, index=False)
study = against_study(table, sm.params.study_run)
study.to_csv(sm.output.against_study, index=False)
Path(sm.output.md).write_text(per_flight_markdown(table, deadline) + "\n"
                              + against_study_markdown(study, sm.params.study_run))
prov = run_provenance(sm.config, manifest)
write_parquet(table, sm.output.parquet, prov)
write_parquet(pd.DataFrame(read_part_rows(sm.input.records)), sm.output.records, prov)
for path in (sm.output.csv, sm.output.md, sm.output.against_study):
    stamp(path, prov)
