"""Snakemake script: docs/index.png, results/index.html as it opens in headless
Chromium at 1400 x 900, checked to show the headline and its figure."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from alfa_bench.workflow.logs import log_to
from alfa_bench.workflow.report_page import open_index

sm = snakemake  # noqa: F821
log_to(sm.log[0])
view = open_index(sm.input[0], sm.output[0])
if (len(view.first_rows) < 2 or not view.images or min(view.images) == 0
        or view.images_in_view < len(view.images) or view.errors):
    raise RuntimeError(f"results/index.html did not open on its headline: {view}")
