"""Snakemake script: the detectability ceiling of single physical features."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.ceiling import ceiling_markdown, ceiling_table
from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import load_cached, read_manifest, subset_flights
from alfa_bench.outputs.provenance import stamp
from alfa_bench.render import markdown_html
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
flights = load_cached(sm.input.cache, manifest)
subsets = {s: subset_flights(manifest, s) for s in sm.params.subsets}
table = ceiling_table(flights, subsets, sm.params.deadline_s, sm.params.margin_s)
table.to_csv(sm.output.csv, index=False)
text = ceiling_markdown(table, sm.params.deadline_s)
Path(sm.output.md).write_text(text)
Path(sm.output.html).write_text(markdown_html(text, "alfa-bench: detectability ceiling"))
prov = run_provenance(sm.config, manifest)
for path in sm.output:
    stamp(path, prov)
