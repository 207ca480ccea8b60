"""The end-of-flight reference: one alarm at the last sample of every flight.

Keipour et al.'s per-flight rule counts any alarm after onset as a detection, however
late. ALFA's fault flights end 9-20 s after an engine onset, so this "detector", which
knows nothing but when the flight ends, scores ~0.77 accuracy on the 22 ICRA 2019
flights without a deadline, and nothing with one. It shows what the metric gives for
lateness alone. It is not causal (no online detector knows the last sample), so it may
only be a reference row.
"""

from __future__ import annotations

import numpy as np

from alfa_bench.data import Sampled

from .base import Detector

__all__ = ["EndOfFlight"]


class EndOfFlight(Detector):
    """Score 1 at the last grid step of the flight, 0 elsewhere; threshold 1/2.

    Parameters
    ----------
    rate_hz : float
        Grid rate of the (measured roll) signal that spans the flight.

    Attributes
    ----------
    steps_ : int
        Steps consumed since :meth:`reset`.
    """

    family = "reference"

    causal = False

    def __init__(self, rate_hz=25.0):
        self.rate_hz = rate_hz

    def signals(self) -> tuple[str, ...]:
        return ("roll",)

    def channels(self) -> tuple[str, ...]:
        return ("end_of_flight",)

    def channel_outputs(self) -> tuple[str, ...]:
        # it scores nothing; the grid's signal stands in
        return ("roll",)

    def thresholds(self) -> np.ndarray:
        return np.array([0.5])

    def reset(self) -> EndOfFlight:
        self.steps_ = 0
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        """A step on its own cannot tell it is the last: it never alarms."""
        self.steps_ += 1
        return np.zeros(1)

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: object | None = None) -> tuple[np.ndarray, dict]:
        """The whole flight at once: the alarm at its last step (from :math:`t = 0`:
        its :meth:`snapshot` is None, so no run continues from a state)."""
        self.reset()
        score = np.zeros((s.t.size, 1))
        score[-1] = 1.0
        self.steps_ = s.t.size
        return score, {}
