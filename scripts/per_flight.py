"""Snakemake script: every run's outcome and margins on every labelled flight, and the
public study's reproduction against its published per-flight table."""

from pathlib import Path

from alfa_bench.analysis import per_flight_markdown, per_flight_table
from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.analysis.public_study import against_study, against_study_markdown
from alfa_bench.data import read_manifest
from alfa_bench.outputs.parquet import records_table, write_parquet
from alfa_bench.outputs.provenance import stamp
from alfa_bench.outputs.records import read_records
from alfa_bench.outputs.traces import read_traces
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
deadline = float(sm.params.deadline_s)
records = read_records(sm.input.detections)
table = per_flight_table(records, read_traces(sm.input.traces, probes=False), manifest,
                         deadline)
table.to_csv(sm.output.csv, index=False)
study = against_study(table, sm.params.study_run)
study.to_csv(sm.output.against_study, index=False)
Path(sm.output.md).write_text(per_flight_markdown(table, deadline) + "\n"
                              + against_study_markdown(study, sm.params.study_run))
prov = run_provenance(sm.config, manifest)
write_parquet(table, sm.output.parquet, prov)
write_parquet(records_table(records), sm.output.records, prov)
for path in (sm.output.csv, sm.output.md, sm.output.against_study):
    stamp(path, prov)
