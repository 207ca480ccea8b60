r"""Observer/Kalman filter identification (OKID) with the eigensystem realization (ERA).

Juang, Phan, Horta, Longman (1993), as used by Heredia and Ollero (2011), Sec. 3. For
the innovations model of a linear system

.. math::

    \hat x(k+1) = A\hat x(k) + B u(k) + L\,e(k), \qquad y(k) = C\hat x(k) + D u(k) + e(k),

the observer :math:`\bar A = A - LC` is asymptotically stable, so with
:math:`v = [u;\,y]` the output is, up to :math:`\bar A^p`,

.. math::

    y(k) = D u(k) + \sum_{i=1}^{p} \bar Y_i\, v(k-i) + e(k), \qquad
    \bar Y_i = C\bar A^{i-1}[\,B - LD,\; L\,] = [\bar Y_i^{(1)},\, \bar Y_i^{(2)}],

a linear regression for the *observer Markov parameters* :math:`\bar Y_i`, solved by
least squares (:func:`observer_markov`). The system Markov parameters
:math:`Y_k = CA^{k-1}B` and the observer-gain Markov parameters
:math:`Y^o_k = CA^{k-1}L` follow by the recursions (:func:`system_markov`)

.. math::

    Y_k &= \bar Y_k^{(1)} + \bar Y_k^{(2)} D + \sum_{i=1}^{k-1} \bar Y_i^{(2)} Y_{k-i},\\
    Y^o_k &= \bar Y_k^{(2)} + \sum_{i=1}^{k-1} \bar Y_i^{(2)} Y^o_{k-i},

with :math:`\bar Y_k = 0` for :math:`k > p`. ERA on the combined sequence
:math:`[Y_k,\, Y^o_k]` (``control.eigensys_realization``) realises
:math:`(A, [B, L], C)` in one balanced coordinate system, so the identified gain
:math:`L` (the steady-state Kalman *predictor* gain when the data's noise is white) is
in the coordinates of :math:`A, B, C`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .base import CalibrationError

__all__ = ["OkidModel", "observer_markov", "okid", "system_markov"]


@dataclass(frozen=True)
class OkidModel:
    """An identified innovations model :math:`(A, B, C, D, L)` and the Hankel
    singular values that chose its order."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    L: np.ndarray
    hankel_sv: np.ndarray


def _regressors(u: np.ndarray, y: np.ndarray, lags: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows k >= p of [u(k), v(k-1), ..., v(k-p)] and the targets y(k)."""
    v = np.hstack([u, y])
    k = np.arange(lags, u.shape[0])
    cols = [u[k]] + [v[k - i] for i in range(1, lags + 1)]
    return np.hstack(cols), y[k]


def observer_markov(segments: list[tuple[np.ndarray, np.ndarray]],
                    lags: int) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares :math:`D` and :math:`\\bar Y_1..\\bar Y_p` from ``(u, y)`` segments.

    ``u`` is (n, m), ``y`` is (n, q). Returns ``D`` (q, m) and ``Ybar`` (p, q, m + q).
    """
    m, q = segments[0][0].shape[1], segments[0][1].shape[1]
    width = m + lags * (m + q)
    gram, cross, rows = np.zeros((width, width)), np.zeros((width, q)), 0
    for u, y in segments:
        if u.shape[0] <= lags:
            continue
        phi, target = _regressors(u, y, lags)
        gram += phi.T @ phi
        cross += phi.T @ target
        rows += target.shape[0]
    if rows < width:
        raise CalibrationError(f"{rows} regression rows cannot fit {width} observer Markov "
                               "parameters; use fewer lags or more data")
    coef, *_ = np.linalg.lstsq(gram, cross, rcond=None)   # y = coef' [u; v(k-1..k-p)]
    coef = coef.T
    return coef[:, :m], coef[:, m:].reshape(q, lags, m + q).transpose(1, 0, 2)


def system_markov(D: np.ndarray, Ybar: np.ndarray, count: int) -> tuple[np.ndarray,
                                                                        np.ndarray]:
    """:math:`Y_1..Y_{count}` (count, q, m) and :math:`Y^o_1..Y^o_{count}` (count, q, q)."""
    lags, q, width = Ybar.shape
    m = width - q
    Y = np.zeros((count, q, m))
    Yo = np.zeros((count, q, q))
    for k in range(1, count + 1):
        if k <= lags:
            Y[k - 1] = Ybar[k - 1, :, :m] + Ybar[k - 1, :, m:] @ D
            Yo[k - 1] = Ybar[k - 1, :, m:]
        for i in range(1, min(k - 1, lags) + 1):
            Y[k - 1] += Ybar[i - 1, :, m:] @ Y[k - i - 1]
            Yo[k - 1] += Ybar[i - 1, :, m:] @ Yo[k - i - 1]
    return Y, Yo


def okid(segments: list[tuple[np.ndarray, np.ndarray]], lags: int, order: int) -> OkidModel:
    """Identify :math:`(A, B, C, D, L)` of the given ``order`` from ``(u, y)`` segments
    with ``lags`` observer Markov parameters."""
    if order < 1 or lags < order:
        raise ValueError(f"need 1 <= order <= lags, got order={order}, lags={lags}")
    D, Ybar = observer_markov(segments, lags)
    q, m = D.shape
    Y, Yo = system_markov(D, Ybar, 2 * lags + 1)
    yy = np.zeros((q, m + q, 2 * lags + 2))               # [D, 0], [Y_1, Yo_1], ...
    yy[:, :m, 0] = D
    yy[:, :, 1:] = np.concatenate([Y, Yo], axis=2).transpose(1, 2, 0)
    # imported here: python-control brings matplotlib (~0.5 s), which only OKID fits need
    import control

    sys, sv = control.eigensys_realization(yy, order, m=lags, n=lags)
    return OkidModel(A=np.asarray(sys.A), B=np.asarray(sys.B)[:, :m], C=np.asarray(sys.C),
                     D=D, L=np.asarray(sys.B)[:, m:], hankel_sv=np.asarray(sv))
