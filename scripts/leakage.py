"""Snakemake script: the leakage audit of every catalogue signal over the flights."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.leakage import leakage_markdown, leakage_table
from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import load_cached, read_manifest
from alfa_bench.outputs.provenance import stamp
from alfa_bench.render import markdown_html
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
flights = load_cached(sm.input.cache, manifest)
table = leakage_table(flights)
table.to_csv(sm.output.csv, index=False)
Path(sm.output.md).write_text(leakage_markdown(table))
Path(sm.output.html).write_text(markdown_html(Path(sm.output.md).read_text(),
                                              "alfa-bench: leakage audit"))
prov = run_provenance(sm.config, manifest)
for path in sm.output:
    stamp(path, prov)
