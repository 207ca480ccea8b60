"""Snakemake script: summary, per-fault and comparison tables (CSV, Markdown, LaTeX)."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

import logging
from pathlib import Path

import pandas as pd

from alfa_bench.analysis.leakage import audit_note
from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.analysis.stability import calibration_table, stability_table
from alfa_bench.data import read_manifest
from alfa_bench.outputs.provenance import read_table, stamp
from alfa_bench.outputs.records import read_failures, read_records
from alfa_bench.outputs.tables import (
    by_fault_latex,
    by_fault_markdown,
    by_fault_table,
    common_ground,
    comparison_latex,
    comparison_markdown,
    comparison_table,
    failures_table,
    left_out_markdown,
    no_fault_note,
    not_applicable_markdown,
    not_applicable_table,
    stability_markdown,
    summary_latex,
    summary_markdown,
    summary_table,
    unscored_notes,
)
from alfa_bench.render import markdown_html
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
records = read_records(sm.input.detections)
failures = failures_table(pd.read_csv(sm.input.load_failures, dtype=str, keep_default_na=False),
                          read_failures(sm.input.detections))
failures.to_csv(sm.output.failures, index=False)
deadline = float(sm.params.deadline_s)
summary = summary_table(records, manifest, sm.params.subsets, deadline, failures)
by_fault = by_fault_table(records, manifest, sm.params.subsets, deadline, failures)
stability = sm.params.stability
comparison = comparison_table(records, manifest, sm.params.subsets, deadline, failures,
                              stability["stable"], stability["interval"])
common, left_out = common_ground(records, manifest, failures)
left_out.to_csv(sm.output.left_out, index=False)
if len(left_out):
    logging.getLogger("alfa_bench.analysis").warning(
        "%d flight(s) left out of the common ground every run is ranked on: %s (see "
        "results/tables/left_out.csv)", len(left_out), ", ".join(left_out["flight"]))
pooled = stability_table(common, manifest, sm.params.subsets, deadline, stability["stable"],
                         stability["interval"])
pooled.to_csv(sm.output.stability, index=False)
folds = calibration_table(records)
folds.to_csv(sm.output.calibration, index=False)
Path(sm.output.stability_md).write_text(stability_markdown(pooled, folds, stability))
summary.to_csv(sm.output.summary, index=False)
by_fault.to_csv(sm.output.by_fault, index=False)
comparison.to_csv(sm.output.comparison, index=False)
Path(sm.output.summary_md).write_text(summary_markdown(summary))
Path(sm.output.by_fault_md).write_text(by_fault_markdown(by_fault))
audit = audit_note(read_table(sm.input.leakage), manifest, sm.params.primary,
                   failures[failures["stage"] == "load"])
if audit.startswith("**WARNING"):
    logging.getLogger("alfa_bench.analysis").warning(audit.replace("*", "").strip())
not_applicable_table(sm.params.not_applicable).to_csv(sm.output.not_applicable, index=False)
Path(sm.output.comparison_md).write_text(comparison_markdown(
    comparison, unscored_notes(comparison, failures, manifest, sm.params.subsets)
    + not_applicable_markdown(sm.params.not_applicable),
    sm.params.primary, no_fault_note(comparison, sm.params.primary) + audit,
    left_out_markdown(left_out, sm.params.subsets)))
Path(sm.output.comparison_html).write_text(markdown_html(
    Path(sm.output.comparison_md).read_text(), "alfa-bench: comparison"))
Path(sm.output.summary_tex).write_text(summary_latex(summary))
Path(sm.output.by_fault_tex).write_text(by_fault_latex(by_fault))
Path(sm.output.comparison_tex).write_text(comparison_latex(comparison))
prov = run_provenance(sm.config, manifest)
for path in sm.output:
    stamp(path, prov)
