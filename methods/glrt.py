r"""Windowed GLRT for a change of mean, and its thresholds (Hansen, Blanke, Adrian 2014).

The hypotheses (eq. 1) on a zero-mean residual :math:`x`, with :math:`w` white
Gaussian of variance :math:`\sigma^2`:

.. math::

    \mathcal H_0: x(i) = w(i), \qquad \mathcal H_1: x(i) = A + w(i)\ \text{for}\ i \ge j.

For a change at instant :math:`j` the log-likelihood ratio (eq. 2) is maximised by the
mean of :math:`x(j..k)`, :math:`\hat A = \frac{1}{k-j+1}\sum_{i=j}^{k} x(i)`, giving

.. math::

    \max_A S_j^k = \frac{\left(\sum_{i=j}^{k} x(i)\right)^2}{2\sigma^2 (k-j+1)},
    \qquad g(k) = \max_{k-M < j \le k} \max_A S_j^k            \quad (3)

over the last :math:`M` samples. :math:`\mathcal H_1` is decided when
:math:`g(k) > \gamma`.

Two thresholds for a false-alarm probability :math:`P_F` per sample:

- :func:`empirical_threshold`, the paper's: the :math:`1-P_F` quantile of :math:`g`
  observed on fault-free data. Valid whatever the residual's correlation and tails.
- :func:`chi2_threshold`, the textbook one: for a *fixed* :math:`j` and IID Gaussian
  :math:`x`, :math:`2S_j^k \sim \chi^2_1`, so :math:`\gamma = \tfrac12 F^{-1}_{\chi^2_1}(1-P_F)`.
  It ignores both the maximum over :math:`j` and the residuals' correlation, so on
  real residuals its false-alarm rate is far above :math:`P_F`.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np
from scipy.special import chdtri

from .base import CalibrationError

__all__ = ["WindowedGlrt", "chi2_threshold", "empirical_threshold", "glrt_statistic"]


class WindowedGlrt:
    """Streaming :math:`g(k)` of eq. (3).

    Parameters
    ----------
    window : int
        :math:`M`, samples searched for the change instant.
    sigma2 : float
        :math:`\\sigma^2` under :math:`\\mathcal H_0`.

    Attributes
    ----------
    g_ : float
        The last :math:`g(k)`.
    change_ : int
        Samples since the maximising change instant :math:`\\hat j` (0 = this one).
    mean_ : float
        :math:`\\hat A` at :math:`\\hat j`.
    """

    def __init__(self, window: int, sigma2: float):
        self.window = window
        self.sigma2 = sigma2

    def reset(self) -> WindowedGlrt:
        if self.window < 1:
            raise ValueError(f"GLRT window must be >= 1 sample, got {self.window}")
        if not self.sigma2 > 0:
            raise ValueError(f"GLRT variance must be > 0, got {self.sigma2}")
        self.x_ = deque(maxlen=self.window)
        self.g_, self.change_, self.mean_ = math.nan, 0, math.nan
        return self

    def update(self, x: float) -> float:
        self.x_.appendleft(x)
        sums = np.cumsum(self.x_)                          # sum_{i=j}^{k} x(i), newest j first
        n = np.arange(1, sums.size + 1)
        s = sums * sums / (2.0 * self.sigma2 * n)          # max_A S_j^k
        best = int(np.argmax(s))
        self.g_, self.change_, self.mean_ = float(s[best]), best, float(sums[best] / n[best])
        return self.g_


def glrt_statistic(x: np.ndarray, window: int, sigma2: float) -> np.ndarray:
    """:math:`g(k)` for every k of ``x`` at once; what :class:`WindowedGlrt` streams."""
    x = np.asarray(x, dtype=float)
    csum = np.r_[0.0, np.cumsum(x)]
    g = np.zeros(x.size)
    for n in range(1, min(window, x.size) + 1):            # change instant j = k - n + 1
        s = csum[n:] - csum[:-n]
        g[n - 1:] = np.maximum(g[n - 1:], s * s / (2.0 * sigma2 * n))
    return g


def empirical_threshold(g: np.ndarray, false_alarm: float) -> float:
    """The :math:`1 - P_F` quantile of fault-free :math:`g` samples (NaN ignored)."""
    g = np.asarray(g, dtype=float)
    g = g[np.isfinite(g)]
    if not 0.0 < false_alarm < 1.0:
        raise ValueError(f"false-alarm probability must be in (0, 1), got {false_alarm}")
    if g.size * false_alarm < 1.0:
        raise CalibrationError(f"{g.size} fault-free samples cannot resolve P_F = "
                               f"{false_alarm}: need at least {math.ceil(1 / false_alarm)}")
    return float(np.quantile(g, 1.0 - false_alarm, method="higher"))


def chi2_threshold(false_alarm: float) -> float:
    """:math:`\\gamma = \\tfrac12 F^{-1}_{\\chi^2_1}(1 - P_F)` (fixed change instant, IID)."""
    # chdtri is the chi-square inverse survival function, what scipy.stats.chi2.isf
    # calls; scipy.stats alone takes ~0.5 s to import, in every job
    return 0.5 * float(chdtri(1, false_alarm))
