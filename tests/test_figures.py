"""The per-flight figures: each method's detect job draws its panel of every flight on a
strip of its own, reusing one drawer, and the figure is the strips stacked; so what the
drawer drew for one flight must not show in the next, and the stack must be the figure
drawn whole."""

import io

import numpy as np
import pytest
from PIL import Image

from alfa_bench.methods import Trace
from alfa_bench.outputs.flight_figures import (
    FlightFrame,
    FlightPanel,
    flight_figure,
    flight_span,
)


def trace(t_end: float, alarm_at: float | None, dt: float = 0.1) -> Trace:
    t = np.arange(0.0, t_end, dt)
    score = np.full((t.size, 1), 0.5)
    if alarm_at is not None:
        score[t >= alarm_at] = 2.0
    score[::7] *= 3.3               # a jagged line, drawn over many pixels
    return Trace(t=t, score=score, alarm=score > 1.0, channels=("c",), threshold=np.ones(1))


def test_a_redrawn_strip_is_the_strip_drawn_afresh(tmp_path):
    reused = FlightPanel("a")
    reused.draw(trace(90.0, 52.0), 50.0, 80.0, flight_span(50.0, 90.0), tmp_path / "faulty.png")
    reused.draw(trace(60.0, 10.0), None, None, flight_span(None, 60.0), tmp_path / "reused.png")
    FlightPanel("a").draw(trace(60.0, 10.0), None, None, flight_span(None, 60.0),
                          tmp_path / "fresh.png")
    png = (tmp_path / "reused.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert png == (tmp_path / "fresh.png").read_bytes()
    assert png != (tmp_path / "faulty.png").read_bytes()


@pytest.mark.parametrize(("onset", "end", "flight_s"),
                         [(50.0, 70.0, 88.0), (20.3, 77.7, 85.1), (None, None, 90.0)])
def test_the_stacked_strips_are_the_figure_drawn_whole(tmp_path, onset, end, flight_s):
    traces = {"a": trace(90.0, 52.0), "a_longer_name": trace(90.0, None, 0.04),
              "c": trace(80.0, 20.0)}
    span = flight_span(onset, flight_s)
    frame = FlightFrame()
    for flight in ("other", "f"):          # the frame, too, is reused
        strips = []
        for method, tr in traces.items():
            strips.append(tmp_path / f"{method}.png")
            FlightPanel(method).draw(tr, onset, end, span, strips[-1])
        frame.draw(flight, span, strips, tmp_path / "f.png")
    whole = io.BytesIO()
    fig = flight_figure("f", onset, end, span, traces)
    fig.savefig(whole, format="rgba", dpi=fig.dpi)
    stacked = np.asarray(Image.open(tmp_path / "f.png"))
    assert stacked.tobytes() == whole.getvalue()
    assert stacked.shape[:2] == (fig.get_figheight() * fig.dpi, fig.get_figwidth() * fig.dpi)
    assert (stacked[..., :3] < 128).any(axis=-1).sum() > 1000       # lines and text, drawn


def test_the_span_is_the_window_around_the_onset_or_the_whole_flight():
    assert flight_span(50.0, 100.0) == (20.0, 80.0)
    assert flight_span(90.0, 100.0) == (60.0, 100.0)
    assert flight_span(None, 100.0) == (0.0, 100.0)
