"""A recording opened in rerun's web viewer in headless Chromium shows the flight and
its fault, not rerun's welcome screen. Skipped, with the reason, where Chromium or
Playwright is missing (Debian: apt-get install chromium)."""

import urllib.request

import numpy as np
import pytest
from unavailable import require_module, unavailable

from alfa_bench.data import load_flight
from alfa_bench.methods import make_detector, run_detector
from alfa_bench.outputs.rerun_log import write_rerun_log
from alfa_bench.workflow.viewer import check_screenshot, chromium, screenshot, serve_recording

require_module("playwright", "Playwright is not installed: the viewer check did not run",
               module_level=True)
if chromium() is None:
    unavailable("no Chromium (apt-get install chromium): the viewer check did not run",
                module_level=True)


def test_the_welcome_screen_is_not_taken_for_a_recording():
    white = np.full((1000, 1600, 3), 250, np.uint8)
    white[60:75, 10:190] = (30, 110, 230)              # the welcome screen's blue pill
    assert not check_screenshot(white).shows_recording


@pytest.mark.slow
def test_the_recording_renders_open_on_the_fault(corpus, tmp_path):
    flight = load_flight(next(p for p in sorted(corpus.iterdir()) if "engine" in p.name))
    detector = make_detector("rls_arx_zscore", {"pairs": [
        {"name": "roll", "input": "roll_cmd", "output": "roll"}]})
    rrd = tmp_path / f"{flight.id}.rrd"
    write_rerun_log(flight, {"rls_arx_zscore": run_detector(detector, flight, probes=True)},
                    ["roll_cmd", "roll", "roll_rate"], rrd, {"inputs": {}})
    with serve_recording(rrd) as url:
        shown = screenshot(url, tmp_path / "viewer.png")
    assert shown.shows_recording, shown
    with pytest.raises(OSError):     # the server is gone with its launcher, not left running
        urllib.request.urlopen(url.split("?")[0], timeout=2)
    # the selected span is the fault's: from the onset to the end of the flight, on a
    # time panel from about 15 % of the width (right of the streams list) to the edge
    onset = flight.fault.onset_s / flight.duration_s
    left, right = shown.selection
    assert left == pytest.approx(0.15 + 0.83 * onset, abs=0.05), (shown, onset)
    assert right > 0.95, shown
