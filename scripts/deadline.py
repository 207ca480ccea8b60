"""Snakemake script: detection rate against the deadline, as a table and a figure."""

from pathlib import Path

from alfa_bench.analysis import read_records
from alfa_bench.analysis.deadline import deadline_figure, deadline_markdown, deadline_table
from alfa_bench.analysis.logs import log_to
from alfa_bench.analysis.provenance import run_provenance, stamp
from alfa_bench.data import read_manifest

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
table = deadline_table(read_records(sm.input.detections), manifest, sm.params.subsets,
                       sm.params.deadlines_s)
table.to_csv(sm.output.csv, index=False)
Path(sm.output.md).write_text(deadline_markdown(table))
deadline_figure(table, sm.params.subset, sm.output.figure)
prov = run_provenance(sm.config, manifest)
for path in sm.output:
    stamp(path, prov)
