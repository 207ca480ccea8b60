r"""ARX regressors, streaming and batch, in the layout of the RLS-ARX detector.

.. math::

    \phi(k) = [\,y(k-1), \dots, y(k-n_a),\; u(k), u(k-1), \dots, u(k-n_b+1)\,]^T,
    \qquad y(k) = \phi^T(k)\,\theta + n(k).
"""

from __future__ import annotations

from collections import deque

import numpy as np

from .base import CalibrationError

__all__ = ["ArxRegressor", "arx_regressors", "fit_arx"]


class ArxRegressor:
    """Streaming :math:`\\phi(k)`: :meth:`push` the inputs of step k, then read
    :meth:`phi`, then :meth:`push_output` :math:`y(k)`."""

    def __init__(self, na: int, nb: int):
        self.na = na
        self.nb = nb

    def reset(self) -> ArxRegressor:
        if self.na < 0 or self.nb < 1:
            raise ValueError(f"need na >= 0 and nb >= 1, got na={self.na}, nb={self.nb}")
        self.u_ = deque(maxlen=self.nb)
        self.y_ = deque(maxlen=max(self.na, 1))
        return self

    def push(self, u: float) -> None:
        self.u_.appendleft(u)

    def ready(self) -> bool:
        return len(self.u_) == self.nb and len(self.y_) >= self.na

    def phi(self) -> np.ndarray:
        return np.fromiter((*list(self.y_)[:self.na], *self.u_), dtype=float,
                           count=self.na + self.nb)

    def push_output(self, y: float) -> None:
        self.y_.appendleft(y)


def arx_regressors(u: np.ndarray, y: np.ndarray, na: int, nb: int) -> tuple[np.ndarray,
                                                                             np.ndarray]:
    """All complete :math:`(\\Phi, y)` rows of one segment (rows k >= max(n_a, n_b - 1))."""
    start = max(na, nb - 1)
    n = u.size - start
    if n <= 0:
        return np.empty((0, na + nb)), np.empty(0)
    k = np.arange(start, u.size)
    cols = [y[k - i] for i in range(1, na + 1)] + [u[k - j] for j in range(nb)]
    return np.column_stack(cols), y[k]


def fit_arx(segments: list[tuple[np.ndarray, np.ndarray]], na: int, nb: int) -> np.ndarray:
    """Least-squares :math:`\\theta` over several ``(u, y)`` segments pooled."""
    gram = np.zeros((na + nb, na + nb))
    cross = np.zeros(na + nb)
    rows = 0
    for u, y in segments:
        phi, target = arx_regressors(u, y, na, nb)
        gram += phi.T @ phi                                # Phi' Phi
        cross += phi.T @ target                            # Phi' y
        rows += target.size
    if rows < na + nb:
        raise CalibrationError(f"{rows} regression rows cannot fit {na + nb} ARX parameters")
    theta, *_ = np.linalg.lstsq(gram, cross, rcond=None)   # (Phi' Phi) theta = Phi' y
    return theta
