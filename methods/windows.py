"""Means over causal windows of a sampled signal, and their steps.

A step is the mean of a signal's fresh values over its last :math:`W` against their
mean over the :math:`B` before,

.. math::

    d(t) = \bar x(t - W, t] - \bar x(t - W - B, t - W],

taken from cumulative sums, so a whole flight costs a few array passes. The residual
bank steps its residuals (:mod:`.residual_bank`), the physical features their signals
(:mod:`.physics`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["step_from_sums", "step_means", "window_steps"]


def window_steps(seconds: float, rate_hz: float) -> int:
    """A span of ``seconds`` in grid steps, at least one."""
    return max(1, round(seconds * rate_hz))


def step_means(values: np.ndarray, have: np.ndarray, nw: int, nb: int) -> np.ndarray:
    """The step :math:`d(t)` (module docstring) at every step: the mean of the rows of
    ``values`` (n, p) marked ``have`` over the last ``nw`` steps minus their mean over
    the ``nb`` steps before; NaN where either window holds none. ``have`` is (n,) or
    (n, p)."""
    have = np.broadcast_to(have.reshape(have.shape[0], -1), values.shape)
    total = np.cumsum(np.where(have, values, 0.0), axis=0)
    count = np.cumsum(have, axis=0)
    n = values.shape[0]
    out = np.full(values.shape, np.nan)
    if n > nw + nb:
        out[nw + nb:] = step_from_sums(total[nw + nb:], total[nb:n - nw], total[:n - nw - nb],
                                       count[nw + nb:], count[nb:n - nw], count[:n - nw - nb])
    return out


def step_from_sums(total_now, total_mid, total_old, count_now, count_mid, count_old):
    """The step :math:`d(t)` (module docstring) from cumulative sums and counts at t,
    t - W and t - W - B; NaN where a window holds no fresh value."""
    n_recent, n_base = count_now - count_mid, count_mid - count_old
    with np.errstate(invalid="ignore", divide="ignore"):
        recent = (total_now - total_mid) / n_recent                # mean over (t - W, t]
        base = (total_mid - total_old) / n_base                    # mean over (t - W - B, t - W]
    return np.where((n_recent > 0) & (n_base > 0), recent - base, np.nan)
