"""Snakemake script: a screenshot of the HTML report open on the comparison, checked in a
browser."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

import logging

from alfa_bench.workflow.logs import log_to
from alfa_bench.workflow.report_page import open_report

sm = snakemake  # noqa: F821
log_to(sm.log[0])
view = open_report(sm.input[0], sm.output[0], "Comparison", "results/tables/comparison.html")
if view.errors or not any("Headline: subset" in f for f in view.frames):
    raise RuntimeError(f"the report did not show the comparison: {view.errors}; see "
                       f"{sm.output[0]}")
logging.getLogger("alfa_bench").info("report: the comparison is shown")
