"""Snakemake script: a screenshot of one recording in rerun's web viewer."""

import logging
from pathlib import Path

from alfa_bench.workflow.logs import log_to
from alfa_bench.workflow.viewer import screenshot, serve_recording

sm = snakemake  # noqa: F821
log_to(sm.log[0])
rrd = Path(sm.input[0]) / f"{sm.params.flight}.rrd"
if not rrd.exists():
    raise FileNotFoundError(f"{rrd}: figures.viewer_flight names no recorded flight")
with serve_recording(rrd) as url:
    shown = screenshot(url, sm.output[0])
if not shown.shows_recording:
    raise RuntimeError(f"the viewer did not show {rrd} ({shown}); see {sm.output[0]}")
logging.getLogger("alfa_bench").info("%s: %s", rrd, shown)
