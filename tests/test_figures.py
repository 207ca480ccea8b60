"""The per-flight figures: one drawer redraws flight after flight, so what it drew for
one flight must not show in the next."""

import io

import numpy as np
import pytest
from PIL import Image

from alfa_bench.analysis.figures import FlightFigure
from alfa_bench.methods import Trace


def trace(t_end: float, alarm_at: float | None) -> Trace:
    t = np.arange(0.0, t_end, 0.1)
    score = np.full((t.size, 1), 0.5)
    if alarm_at is not None:
        score[t >= alarm_at] = 2.0
    return Trace(t=t, score=score, alarm=score > 1.0, channels=("c",), threshold=np.ones(1))


def test_a_redrawn_figure_is_the_figure_drawn_afresh(tmp_path):
    faulty = {"a": trace(90.0, 52.0), "b": trace(90.0, None)}
    fault_free = {"a": trace(60.0, None), "b": trace(60.0, 10.0)}
    reused = FlightFigure(["a", "b"])
    reused.draw("faulty", 50.0, 80.0, faulty, tmp_path / "faulty.png")
    reused.draw("free", None, None, fault_free, tmp_path / "free_reused.png")
    reused.close()
    fresh = FlightFigure(["a", "b"])
    fresh.draw("free", None, None, fault_free, tmp_path / "free_fresh.png")
    fresh.close()
    png = (tmp_path / "free_reused.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert png == (tmp_path / "free_fresh.png").read_bytes()
    assert png != (tmp_path / "faulty.png").read_bytes()


def test_the_figure_drawn_over_its_background_is_the_full_drawing(tmp_path):
    drawer = FlightFigure(["a", "b", "c"])
    drawer.draw("f", 50.0, 70.0, {"a": trace(90.0, 52.0), "b": trace(90.0, None),
                                  "c": trace(80.0, 20.0)}, tmp_path / "f.png")
    for artist in drawer.fig.findobj():     # a full drawing of every artist
        artist.set_animated(False)
    full = io.BytesIO()
    drawer.fig.savefig(full, format="rgba", dpi=drawer.fig.dpi)
    drawer.close()
    drawn = np.asarray(Image.open(tmp_path / "f.png"))
    assert drawn.tobytes() == full.getvalue()
    assert (drawn[..., :3] < 128).any(axis=-1).sum() > 1000       # lines and text, drawn


def test_traces_of_other_methods_than_the_panels_are_refused(tmp_path):
    drawer = FlightFigure(["a", "b"])
    with pytest.raises(ValueError, match="f: traces of \\['b', 'a'\\]"):
        drawer.draw("f", None, None, {"b": trace(5.0, None), "a": trace(5.0, None)},
                    tmp_path / "f.png")
    drawer.close()
