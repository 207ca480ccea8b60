r"""A two-sided CUSUM on one signal's deviation, as an alfa-bench plugin.

The signal (by default ``roll_error``, the measured minus the commanded roll) is
standardised by its fault-free mean :math:`\mu` and deviation :math:`\sigma`, and
accumulated on fresh measurements only:

.. math::

    z = (x - \mu) / \sigma, \qquad
    g^+ \leftarrow \max(0, g^+ + z - k), \qquad g^- \leftarrow \max(0, g^- - z - k)

with drift :math:`k` (half the shift to detect, in standard deviations). The score is
:math:`\max(g^+, g^-)`; its threshold is the largest score on the fault-free training
flights, times ``margin``.
"""

import numpy as np

from alfa_bench.methods import Detector


class Cusum(Detector):
    """Two-sided CUSUM of one signal (module docstring)."""

    calibrated = True

    def __init__(self, signal="roll_error", drift=0.5, margin=1.2, rate_hz=20.0):
        self.signal = signal
        self.drift = drift
        self.margin = margin
        self.rate_hz = rate_hz

    def signals(self):
        return (self.signal,)

    def channels(self):
        return ("cusum",)

    def channel_outputs(self):
        return (self.signal,)

    def fit(self, segments):
        x = np.concatenate([s.x[s.fresh[:, 0], 0] for s in segments])
        self.mean_, self.std_ = float(np.mean(x)), float(np.std(x)) or 1.0
        peak = max(float(np.max(self.run(s)[0])) for s in segments)
        self.gamma_ = self.margin * max(peak, 1e-9)
        return self

    def fitted(self):
        self._check_fitted("gamma_")
        return {"mean": self.mean_, "std": self.std_, "gamma": self.gamma_}

    def thresholds(self):
        self._check_fitted("gamma_")
        return np.array([self.gamma_])

    def reset(self):
        self._check_fitted("mean_")
        self.g_ = np.zeros(2)                     # g+, g-
        return self

    def update(self, x, fresh):
        if fresh[0]:
            z = (x[0] - self.mean_) / self.std_
            self.g_ = np.maximum(0.0, self.g_ + np.array([z, -z]) - self.drift)
        return np.array([self.g_.max()])
