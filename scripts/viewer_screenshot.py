"""Snakemake script: a screenshot of one flight's recording in rerun's web viewer, its
parts opened together."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

import logging
from pathlib import Path

from alfa_bench.workflow.logs import log_to
from alfa_bench.workflow.viewer import screenshot, serve_recording

sm = snakemake  # noqa: F821
log_to(sm.log[0])
flight = sm.params.flight
own = Path(sm.input.flights) / f"{flight}.rrd"
if not own.exists():
    raise FileNotFoundError(f"{own}: figures.viewer_flight names no recorded flight")
# the flight's own part, then each run's that scored it
rrds = [own, *(p for d in sm.input.runs if (p := Path(d) / f"{flight}.rrd").exists())]
with serve_recording(*rrds) as url:
    shown = screenshot(url, sm.output[0])
if not shown.shows_recording:
    raise RuntimeError(f"the viewer did not show {flight}'s recording ({shown}); see "
                       f"{sm.output[0]}")
logging.getLogger("alfa_bench").info("%s: %s", flight, shown)
