r"""Running mean and variance by Welford's method (Keipour et al., eq. 8).

.. math::

    \bar x_n &= \bar x_{n-1} + (x_n - \bar x_{n-1}) / n\\
    M_{2,n} &= M_{2,n-1} + (x_n - \bar x_{n-1})(x_n - \bar x_n)\\
    s_n^2 &= M_{2,n} / (n - 1)
"""

from __future__ import annotations

import math

__all__ = ["Welford"]


class Welford:
    """Numerically stable running mean and sample variance.

    Attributes
    ----------
    n_ : int
    mean_ : float
    m2_ : float
    """

    def __init__(self):
        self.reset()

    def reset(self) -> Welford:
        self.n_, self.mean_, self.m2_ = 0, 0.0, 0.0
        return self

    def update(self, x: float) -> None:
        self.n_ += 1
        delta = x - self.mean_
        self.mean_ += delta / self.n_         # mean_n = mean_{n-1} + (x - mean_{n-1}) / n
        self.m2_ += delta * (x - self.mean_)  # M2_n += (x - mean_{n-1})(x - mean_n)

    @property
    def variance(self) -> float:
        """Sample variance :math:`s_n^2`; NaN for fewer than two samples."""
        return self.m2_ / (self.n_ - 1) if self.n_ > 1 else math.nan
