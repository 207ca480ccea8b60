r"""The emulation oracle: a reference that reads the fault emulation, not the fault.

ALFA emulates a failure by overriding the failed actuator's output: at onset its servo
channel in ``rc-out`` stops moving, and at an engine failure the throttle drops to
zero. A jammed surface or a dead engine would leave the autopilot's commands moving,
so watching these signals detects the label. This reference shows how far that
leakage alone goes: it is ranked apart from the methods, always.

Per actuator signal :math:`a` (every servo channel and the ``vfr_hud`` throttle), the
score is the time the value has stayed unchanged,

.. math:: s_a(k) = (k - k_a) / f_s, \qquad k_a = \max\{j \le k : a(j) \ne a(j-1)\},

and the ``throttle_zero`` channel scores the time the throttle has been exactly 0.
Channel :math:`c` alarms when :math:`s_c(k) > T_c`. :math:`T_c` is fitted on fault-free
data only: the longest such spell seen on the training segments, so that no training
flight would have alarmed. A channel never seen moving in training (constant over
every segment) has no threshold to learn and never alarms.

The grid is 10 Hz: the servo outputs come at ~3 Hz and ``vfr_hud`` at ~2.5 Hz, so a
moving channel's score stays below ~0.4 s.
"""

from __future__ import annotations

import math

import numpy as np

from alfa_bench.data import Sampled

from .base import Detector

__all__ = ["ACTUATORS", "EmulationOracle"]

#: every actuator signal of the catalogue
ACTUATORS = ("servo_elevator", "servo_throttle", "servo_rudder", "servo_aileron_left",
             "servo_aileron_right", "throttle")


def _spells(x: np.ndarray, fresh: np.ndarray, rate_hz: float) -> tuple[np.ndarray, np.ndarray]:
    """Per step, the seconds since each column last changed, and since the throttle
    (last column) became zero (0 while it is not)."""
    n, m = x.shape
    flat, zero = np.empty((n, m)), np.empty(n)
    since = np.zeros(m)
    zero_since = -1
    for k in range(n):
        since = np.where(fresh[k], 0.0, since + 1.0)
        flat[k] = since / rate_hz
        zero_since = (k if zero_since < 0 else zero_since) if x[k, -1] == 0.0 else -1
        zero[k] = 0.0 if zero_since < 0 else (k - zero_since) / rate_hz
    return flat, zero


class EmulationOracle(Detector):
    """Flat actuator outputs and zero throttle, timed against fault-free spells.

    Parameters
    ----------
    rate_hz : float
        Grid rate.

    Attributes
    ----------
    limits_ : ndarray, shape (c,)
        :math:`T_c`, the longest spell per channel on the training data, s (inf where a
        channel never moved in training).
    steps_ : int
        Steps consumed since :meth:`reset`.
    """

    family = "reference"

    calibrated = True

    def __init__(self, rate_hz=10.0):
        self.rate_hz = rate_hz

    def signals(self) -> tuple[str, ...]:
        return ACTUATORS

    def channels(self) -> tuple[str, ...]:
        return (*(f"{a}_flat" for a in ACTUATORS), "throttle_zero")

    def channel_outputs(self) -> tuple[str, ...]:
        return (*ACTUATORS, "throttle")

    def fit(self, segments: list[Sampled]) -> EmulationOracle:
        self.__dict__.pop("limits_", None)
        longest = np.zeros(len(self.channels()))
        moved = np.zeros(len(self.channels()), dtype=bool)
        for s in segments:
            flat, zero = _spells(s.x, s.fresh, self.rate_hz)
            spells = np.column_stack([flat, zero])
            longest = np.maximum(longest, spells.max(axis=0, initial=0.0))
            moved |= np.r_[s.fresh[1:].any(axis=0), s.fresh[1:, -1].any()]
        self.limits_ = np.where(moved, longest, np.inf)
        return self

    def fitted(self) -> dict:
        self._check_fitted("limits_")
        return {ch: (float(v) if math.isfinite(v) else None)
                for ch, v in zip(self.channels(), self.limits_, strict=True)}

    def thresholds(self) -> np.ndarray:
        self._check_fitted("limits_")
        # a spell no longer than the longest in training never alarms; 1/(2 f_s) keeps
        # a channel that was flat for one step in training above zero
        return np.maximum(self.limits_, 0.5 / self.rate_hz)

    def reset(self) -> EmulationOracle:
        self._check_fitted("limits_")
        self.steps_ = 0
        self.since_ = np.zeros(len(ACTUATORS))
        self.zero_since_ = -1
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        k = self.steps_
        self.since_ = np.where(fresh, 0.0, self.since_ + 1.0)
        if x[-1] == 0.0:
            self.zero_since_ = k if self.zero_since_ < 0 else self.zero_since_
        else:
            self.zero_since_ = -1
        zero = 0.0 if self.zero_since_ < 0 else (k - self.zero_since_) / self.rate_hz
        self.steps_ = k + 1
        score = np.r_[self.since_ / self.rate_hz, zero]
        return score

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: object | None = None) -> tuple[np.ndarray, dict]:
        """:meth:`update` over ``s``, on whole columns, from :math:`t = 0` (its
        :meth:`snapshot` is None, so no run continues from a state)."""
        self.reset()
        flat, zero = _spells(s.x, s.fresh, self.rate_hz)
        score = np.column_stack([flat, zero])
        self.steps_ = s.t.size
        return score, {}
