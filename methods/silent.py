"""The line every run must beat: a detector that arms and never alarms.

It reads one measured signal and scores minus its size from the first step (armed):
never above 0, while its threshold is 1, so no flight ever alarms (the score follows the
data only so that the contract's checks can see causality). Under the deadline it is
right on every fault-free flight and wrong on every fault; a run whose accuracy is no
higher has learned nothing the tables can credit (``beats_silence`` in the comparison).
"""

from __future__ import annotations

import numpy as np

from alfa_bench.data import Sampled

from .base import Detector

__all__ = ["Silent"]


class Silent(Detector):
    """Armed on the roll from the first step, never alarming (module docstring)."""

    family = "reference"

    def signals(self) -> tuple[str, ...]:
        return ("roll",)

    def thresholds(self) -> np.ndarray:
        return np.ones(1)

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        return -np.abs(x[:1])

    def run(self, s: Sampled, probes: bool = False, start: int = 0, state: object | None = None
            ) -> tuple[np.ndarray, dict]:
        # the batch form: it has no state, so any step continues from any other
        return -np.abs(s.x[start:, :1]), {}
