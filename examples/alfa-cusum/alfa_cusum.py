r"""A two-sided CUSUM on one signal's deviation, as an alfa-bench plugin.

The signal (by default ``roll_error``, the measured minus the commanded roll) is
standardised by its fault-free mean :math:`\mu` and deviation :math:`\sigma`, and
accumulated on fresh measurements only:

.. math::

    z = (x - \mu) / \sigma, \qquad
    g^+ \leftarrow \max(0, g^+ + z - k), \qquad g^- \leftarrow \max(0, g^- - z - k)

with drift :math:`k` (half the shift to detect, in standard deviations). The score is
:math:`\max(g^+, g^-)`; its threshold comes from its per-flight maxima on the
fault-free training flights, at a false-alarm rate per flight
(:class:`~alfa_bench.methods.MaximaThresholds`).
"""

import numpy as np

from alfa_bench.methods import Detector, MaximaThresholds


class Cusum(MaximaThresholds, Detector):
    """Two-sided CUSUM of one signal (module docstring)."""

    def __init__(self, signal="roll_error", drift=0.5, false_alarm=0.1):
        self.signal = signal
        self.drift = drift
        self.false_alarm = false_alarm

    def signals(self):
        return (self.signal,)

    def fit_model(self, segments):
        x = np.concatenate([s.x[s.fresh[:, 0], 0] for s in segments])
        self.mean_, self.std_ = float(np.mean(x)), float(np.std(x)) or 1.0
        return self

    def reset(self):
        self.g_ = np.zeros(2)                     # g+, g-
        return self

    def update(self, x, fresh):
        if fresh[0]:
            z = (x[0] - self.mean_) / self.std_
            self.g_ = np.maximum(0.0, self.g_ + np.array([z, -z]) - self.drift)
        return np.array([self.g_.max()])
