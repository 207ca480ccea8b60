"""Snakemake script: the runtime table of the detector jobs."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import read_manifest
from alfa_bench.outputs.provenance import stamp
from alfa_bench.outputs.records import count_records
from alfa_bench.render import markdown_html
from alfa_bench.workflow.logs import log_to
from alfa_bench.workflow.runtime import runtime_markdown, runtime_table

sm = snakemake  # noqa: F821
log_to(sm.log[0])
# one record per flight scored: counted, not read (the injected grid has thousands)
flights, injected = ({Path(d).name: count_records(d) for d in folders}
                     for folders in (sm.input.detections, sm.input.injected))
table = runtime_table(sm.input.benchmarks, flights, injected)
table.to_csv(sm.output.csv, index=False)
Path(sm.output.md).write_text(runtime_markdown(table))
Path(sm.output.html).write_text(markdown_html(Path(sm.output.md).read_text(),
                                              "alfa-bench: runtime"))
prov = run_provenance(sm.config, read_manifest(sm.input.manifest))
for path in sm.output:
    stamp(path, prov)
