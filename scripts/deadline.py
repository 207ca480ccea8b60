"""Snakemake script: detection rate against the deadline, as a table and a figure, and
the detection times by fault class."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.deadline import deadline_markdown, deadline_table
from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import read_manifest, subset_flights
from alfa_bench.outputs.figures import deadline_figure, detection_time_figure
from alfa_bench.outputs.provenance import stamp
from alfa_bench.outputs.records import read_records
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
records = read_records(sm.input.detections)
table = deadline_table(records, manifest, sm.params.subsets, sm.params.deadlines_s)
table.to_csv(sm.output.csv, index=False)
Path(sm.output.md).write_text(deadline_markdown(table))
deadline_figure(table, sm.params.subset, sm.output.figure)
detection_time_figure(records, subset_flights(manifest, sm.params.subset),
                      float(sm.params.deadline_s), sm.output.detection_time)
prov = run_provenance(sm.config, manifest)
for path in sm.output:
    stamp(path, prov)
