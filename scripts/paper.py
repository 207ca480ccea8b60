"""Snakemake script: the manuscript's numbers (LaTeX macros) and its Markdown twin."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import read_manifest
from alfa_bench.outputs.paper import latex_keys, latex_macros, paper_numbers, render_markdown
from alfa_bench.outputs.provenance import read_table, stamp
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
numbers = paper_numbers(read_table(sm.input.comparison), read_table(sm.input.sweep),
                        read_table(sm.input.leakage), read_table(sm.input.by_fault),
                        read_table(sm.input.per_flight), methods=list(sm.config["methods"]),
                        subsets=sm.config["subsets"], primary=sm.config["primary_subset"],
                        sensors={k: read_table(sm.input[k]) for k in (
                            "detectability", "isolation_sensors", "isolation_actuators")},
                        ceiling=read_table(sm.input.ceiling),
                        calibration=read_table(sm.input.calibration),
                        stability=sm.config["stability"],
                        study=read_table(sm.input.against_study),
                        left_out=read_table(sm.input.left_out))
unknown = latex_keys(Path(sm.input.tex).read_text()) - set(numbers)
# on a corpus of logs, a quote of a run not applicable to it, or of an ALFA-only subset,
# says so (workflow/corpus.py); any other missing result is the manuscript's error
absent = {*sm.config.get("not_applicable", {}),
          *({"icra22", "emr"} - set(sm.config["subsets"]) if sm.config.get("corpus") else ())}
numbers.update({k: "n/a" for k in unknown if absent & set(k.split(":"))})
unknown -= set(numbers)
if unknown:
    raise KeyError(f"{sm.input.tex} quotes results no run defines: {sorted(unknown)}")
Path(sm.output.macros).write_text(latex_macros(numbers))
Path(sm.output.markdown).write_text(
    render_markdown(Path(sm.input.markdown).read_text(), numbers, Path.cwd()))
prov = run_provenance(sm.config, read_manifest(sm.input.manifest))
for path in sm.output:
    stamp(path, prov)
