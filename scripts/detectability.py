"""Snakemake script: the detectability table and curves of the injected sensor faults."""

from pathlib import Path

from alfa_bench.analysis import read_records
from alfa_bench.analysis.detectability import (
    detectability_figure,
    detectability_markdown,
    detectability_table,
)
from alfa_bench.analysis.detections import iter_records
from alfa_bench.data import read_manifest
from alfa_bench.outputs.provenance import run_provenance, stamp
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
real = read_manifest(sm.input.calibrate_on)
table = detectability_table(iter_records(sm.input.detections), manifest,
                            read_records(sm.input.clean))
table.to_csv(sm.output.csv, index=False)
Path(sm.output.md).write_text(detectability_markdown(table))
detectability_figure(table, sm.output.figure)
prov = run_provenance(sm.config, manifest, real)
for path in sm.output:
    stamp(path, prov)
