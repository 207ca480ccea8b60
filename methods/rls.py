r"""Recursive least squares, as in Keipour et al. (ICRA 2019), eqs. (4)-(7).

For the linear regression :math:`y(k) = \phi^T(k)\theta + n(k)`:

.. math::

    \hat e(k) &= y(k) - \phi^T(k)\hat\theta(k-1)                          && (4)\\
    K(k) &= \frac{P(k-1)\phi(k)}{\lambda + \phi^T(k)P(k-1)\phi(k)}        && (5)\\
    \hat\theta(k) &= \hat\theta(k-1) + K(k)\hat e(k)                     && (6)\\
    P(k) &= \left(P(k-1) - K(k)\phi^T(k)P(k-1)\right)/\lambda            && (7)

with :math:`\hat\theta(0) = 0` and :math:`P(0) = p_0 I`. The paper writes the
covariance :math:`C` and the gain :math:`L`; here they carry filterpy's names, as in
every kernel. The paper's form is
:math:`\lambda = 1`; :math:`\lambda < 1` is the exponential forgetting used by
Hansen et al. With :math:`\lambda = 1` the estimate after :math:`k` steps is
exactly the ridge solution
:math:`(\Phi^T\Phi + I/p_0)^{-1}\Phi^T y`, which the tests use as reference.

With :math:`\lambda < 1` and a regressor that stops varying (level flight, a held
command), (7) divides the unexcited directions of :math:`P` by :math:`\lambda` at
every step: the covariance winds up as :math:`\lambda^{-k}` and the next excitation
throws :math:`\hat\theta` about. ``max_trace`` guards against this: whenever
:math:`\operatorname{tr} P(k)` exceeds it, :math:`P(k)` is scaled back onto
:math:`\operatorname{tr} P = ` ``max_trace`` (a bounded-trace forgetting).
"""

from __future__ import annotations

import numpy as np

from . import kernels

__all__ = ["RecursiveLeastSquares"]


class RecursiveLeastSquares:
    """RLS estimator with optional forgetting factor.

    Parameters
    ----------
    n_params : int
        Length of the regressor :math:`\\phi`.
    p0 : float
        Initial covariance :math:`P(0) = p_0 I`; large means little trust in
        :math:`\\hat\\theta(0) = 0`.
    forgetting : float
        :math:`\\lambda \\in (0, 1]`.
    max_trace : float
        Bound on :math:`\\operatorname{tr} P(k)`; ``inf`` for none.

    Attributes
    ----------
    theta_ : ndarray
        :math:`\\hat\\theta(k)`, updated in place.
    P_ : ndarray
        :math:`P(k)`, updated in place.
    error_, K_, step_ : float, ndarray, ndarray
        :math:`\\hat e(k)`, :math:`K(k)` and :math:`K(k)\\hat e(k)` of the last update.
    """

    def __init__(self, n_params: int, p0: float = 1e6, forgetting: float = 1.0,
                 max_trace: float = np.inf):
        self.n_params = n_params
        self.p0 = p0
        self.forgetting = forgetting
        self.max_trace = max_trace

    def reset(self, theta: np.ndarray | None = None,
              P: np.ndarray | None = None) -> RecursiveLeastSquares:
        """Start from :math:`\\hat\\theta(0)` = ``theta`` (zeros) and
        :math:`P(0)` = ``P`` (:math:`p_0 I`)."""
        if not 0.0 < self.forgetting <= 1.0:
            raise ValueError(f"forgetting must be in (0, 1], got {self.forgetting}")
        if not self.max_trace > 0:
            raise ValueError(f"max_trace must be > 0, got {self.max_trace}")
        self.theta_ = np.zeros(self.n_params) if theta is None else np.array(theta, float)
        self.P_ = np.eye(self.n_params) * self.p0 if P is None else np.array(P, float)
        self.error_ = np.nan
        self.K_ = np.zeros(self.n_params)
        self.step_ = np.zeros(self.n_params)
        self._P_phi = np.zeros(self.n_params)
        return self

    def update(self, phi: np.ndarray, y: float) -> float:
        """One RLS step (in place on ``theta_`` and ``P_``, by the compiled
        :func:`~.kernels.rls_update`); returns the a-priori error :math:`\\hat e(k)`."""
        e = kernels.rls_update(self.theta_, self.P_, np.asarray(phi, dtype=float), float(y),
                               float(self.forgetting), float(self.max_trace), self._P_phi,
                               self.K_)
        self.error_ = e
        self.step_ = self.K_ * e
        return e
