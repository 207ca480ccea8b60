"""A recording opened in rerun's web viewer in headless Chromium shows the flight and
its fault, not rerun's welcome screen, also when opened from its parts. Skipped, with
the reason, where Chromium or Playwright is missing (Debian: apt-get install
chromium)."""

import urllib.request

import numpy as np
import pytest
from unavailable import require_module, unavailable

from alfa_bench.data import load_flight
from alfa_bench.methods import make_detector, run_detector
from alfa_bench.outputs.rerun_log import write_flight_part, write_rerun_log, write_run_part
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
@pytest.mark.parametrize("parts", [False, True], ids=["whole", "parts"])
def test_the_recording_renders_open_on_the_fault(corpus, tmp_path, parts):
    """Written whole, or as the workflow writes it: the flight's part and a run's, the
    run's given first, so that the viewer meets the layout after the data."""
    flight = load_flight(next(p for p in sorted(corpus.iterdir()) if "engine" in p.name))
    detector = make_detector("rls_arx_zscore", {"pairs": [
        {"name": "roll", "input": "roll_cmd", "output": "roll"}]})
    trace = run_detector(detector, flight, probes=True)
    signals = ["roll_cmd", "roll", "roll_rate"]
    if parts:
        rrds = [tmp_path / "rls_arx_zscore.rrd", tmp_path / "flight.rrd"]
        write_run_part(flight.id, "rls_arx_zscore", trace, rrds[0], {"inputs": {}})
        write_flight_part(flight, ["rls_arx_zscore"], signals, rrds[1], {"inputs": {}})
    else:
        rrds = [tmp_path / f"{flight.id}.rrd"]
        write_rerun_log(flight, {"rls_arx_zscore": trace}, signals, rrds[0], {"inputs": {}})
    with serve_recording(*rrds) as url:
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
