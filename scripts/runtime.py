"""Snakemake script: the runtime table of the detector jobs."""

from collections import Counter
from pathlib import Path

from alfa_bench.analysis import read_records
from alfa_bench.analysis.logs import log_to
from alfa_bench.analysis.provenance import run_provenance, stamp
from alfa_bench.analysis.runtime import runtime_markdown, runtime_table
from alfa_bench.data import read_manifest

sm = snakemake  # noqa: F821
log_to(sm.log[0])
flights = Counter(r["method"] for r in read_records(sm.input.detections))
table = runtime_table(sm.input.benchmarks, flights)
table.to_csv(sm.output.csv, index=False)
Path(sm.output.md).write_text(runtime_markdown(table))
prov = run_provenance(sm.config, read_manifest(sm.input.manifest))
for path in sm.output:
    stamp(path, prov)
