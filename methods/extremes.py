"""Thresholds from per-flight maxima: a capped Gumbel law.

A detector whose false alarms are budgeted per flight, not per sample, reads its
threshold from the maxima of its score over fault-free segments (:mod:`.residual_bank`,
:mod:`.learned_fusion`, :mod:`.coincidence`).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["CAP_LEVEL", "gumbel_threshold"]

#: per-flight maxima are capped at this quantile of the law their quartiles give
#: (:func:`gumbel_threshold`): one fault-free flight in a thousand would exceed it
CAP_LEVEL = 0.999


def _gumbel_unit(p: float) -> float:
    """The Gumbel law's quantile function in units of its scale: Q(p) = mu + beta g(p)."""
    return -math.log(-math.log(p))


def gumbel_threshold(maxima: np.ndarray, level: float) -> float:
    r"""The ``level`` quantile of a Gumbel law fitted (maximum likelihood) to the
    per-flight ``maxima``, each capped first so that one extreme flight cannot move it
    far. The cap is the :data:`CAP_LEVEL` quantile of the law fitted by the quartiles
    :math:`q_p`, which one flight moves by at most one order statistic:

    .. math::

        \mathrm{cap} = q_{1/2} + (q_{3/4} - q_{1/4})\,
        \frac{g(p_{\mathrm{cap}}) - g(1/2)}{g(3/4) - g(1/4)}, \qquad g(p) = -\ln(-\ln p).

    Maxima like the others lie far below it, and are fitted as they are; an absurd one
    weighs as a flight at the cap does."""
    from scipy import stats  # ~0.5 s to import: only where a Gumbel law is fitted

    maxima = np.asarray(maxima, dtype=float)
    q1, q2, q3 = np.quantile(maxima, [0.25, 0.5, 0.75])
    cap = q2 + (q3 - q1) * (_gumbel_unit(CAP_LEVEL) - _gumbel_unit(0.5)) / (
        _gumbel_unit(0.75) - _gumbel_unit(0.25))
    loc, scale = stats.gumbel_r.fit(np.minimum(maxima, cap))
    return float(stats.gumbel_r.ppf(level, loc, scale))
