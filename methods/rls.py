r"""Recursive least squares, as in Keipour et al. (ICRA 2019), eqs. (4)-(7).

For the linear regression :math:`y(k) = \phi^T(k)\theta + n(k)`:

.. math::

    \hat e(k) &= y(k) - \phi^T(k)\hat\theta(k-1)                          && (4)\\
    L(k) &= \frac{C(k-1)\phi(k)}{\lambda + \phi^T(k)C(k-1)\phi(k)}        && (5)\\
    \hat\theta(k) &= \hat\theta(k-1) + L(k)\hat e(k)                     && (6)\\
    C(k) &= \left(C(k-1) - L(k)\phi^T(k)C(k-1)\right)/\lambda            && (7)

with :math:`\hat\theta(0) = 0` and :math:`C(0) = p_0 I`. The paper's form is
:math:`\lambda = 1`; :math:`\lambda < 1` is the exponential forgetting used by
Hansen et al. With :math:`\lambda = 1` the estimate after :math:`k` steps is
exactly the ridge solution
:math:`(\Phi^T\Phi + I/p_0)^{-1}\Phi^T y`, which the tests use as reference.

With :math:`\lambda < 1` and a regressor that stops varying (level flight, a held
command), (7) divides the unexcited directions of :math:`C` by :math:`\lambda` at
every step: the covariance winds up as :math:`\lambda^{-k}` and the next excitation
throws :math:`\hat\theta` about. ``max_trace`` guards against this: whenever
:math:`\operatorname{tr} C(k)` exceeds it, :math:`C(k)` is scaled back onto
:math:`\operatorname{tr} C = ` ``max_trace`` (a bounded-trace forgetting).
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
        Initial covariance :math:`C(0) = p_0 I`; large means little trust in
        :math:`\\hat\\theta(0) = 0`.
    forgetting : float
        :math:`\\lambda \\in (0, 1]`.
    max_trace : float
        Bound on :math:`\\operatorname{tr} C(k)`; ``inf`` for none.

    Attributes
    ----------
    theta_ : ndarray
        :math:`\\hat\\theta(k)`, updated in place.
    cov_ : ndarray
        :math:`C(k)`, updated in place.
    error_, gain_, step_ : float, ndarray, ndarray
        :math:`\\hat e(k)`, :math:`L(k)` and :math:`L(k)\\hat e(k)` of the last update.
    """

    def __init__(self, n_params: int, p0: float = 1e6, forgetting: float = 1.0,
                 max_trace: float = np.inf):
        self.n_params = n_params
        self.p0 = p0
        self.forgetting = forgetting
        self.max_trace = max_trace

    def reset(self, theta: np.ndarray | None = None,
              cov: np.ndarray | None = None) -> RecursiveLeastSquares:
        """Start from :math:`\\hat\\theta(0)` = ``theta`` (zeros) and
        :math:`C(0)` = ``cov`` (:math:`p_0 I`)."""
        if not 0.0 < self.forgetting <= 1.0:
            raise ValueError(f"forgetting must be in (0, 1], got {self.forgetting}")
        if not self.max_trace > 0:
            raise ValueError(f"max_trace must be > 0, got {self.max_trace}")
        self.theta_ = np.zeros(self.n_params) if theta is None else np.array(theta, float)
        self.cov_ = np.eye(self.n_params) * self.p0 if cov is None else np.array(cov, float)
        self.error_ = np.nan
        self.gain_ = np.zeros(self.n_params)
        self.step_ = np.zeros(self.n_params)
        self._c_phi = np.zeros(self.n_params)
        return self

    def update(self, phi: np.ndarray, y: float) -> float:
        """One RLS step (in place on ``theta_`` and ``cov_``, by the compiled
        :func:`~.kernels.rls_update`); returns the a-priori error :math:`\\hat e(k)`."""
        e = kernels.rls_update(self.theta_, self.cov_, np.asarray(phi, dtype=float), float(y),
                               float(self.forgetting), float(self.max_trace), self._c_phi,
                               self.gain_)
        self.error_ = e
        self.step_ = self.gain_ * e
        return e
