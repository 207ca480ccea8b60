r"""Thresholds from per-flight maxima: a capped Gumbel law.

A detector whose false alarms are budgeted per flight, not per sample, reads its
threshold from the maxima of its score over fault-free segments: it writes its
scoring, and :class:`MaximaThresholds` the rest (:mod:`.residual_bank`,
:mod:`.learned_fusion`, :mod:`.coincidence`). For each channel :math:`c` of the
:math:`C`, the maxima :math:`M_{c,j} = \max_t s_c(t)` over the fault-free training
segments :math:`j` are fitted with a Gumbel law, each capped first so that one extreme
flight moves it little (:func:`gumbel_threshold`), and

.. math::

    \gamma_c = F^{-1}_{\mathrm{Gumbel}}(1 - \alpha / C;\ \hat\mu_c, \hat\beta_c)

so that a fault-free flight like the training ones alarms on any channel with
probability about :math:`\alpha` (Bonferroni).
"""

from __future__ import annotations

import math

import numpy as np

from .base import CalibrationError, json_ready, learned_state

__all__ = ["CAP_LEVEL", "MIN_SEGMENTS", "MaximaThresholds", "gumbel_threshold",
           "gumbel_thresholds"]

#: fewer per-flight maxima than this cannot fit a two-parameter law
MIN_SEGMENTS = 3

#: per-flight maxima are capped at this quantile of the law their quartiles give
#: (:func:`gumbel_threshold`): one fault-free flight in a thousand would exceed it
CAP_LEVEL = 0.999


def _flat(low, high):
    """Whether values between ``low`` and ``high`` do not vary, to rounding."""
    return high - low <= 1e-12 * np.maximum(1.0, np.maximum(np.abs(low), np.abs(high)))


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
    weighs as a flight at the cap does.

    Raises
    ------
    CalibrationError
        Where the capped maxima do not vary (a score that is constant, or the same on
        most flights): a law with no spread cannot be fitted, and no finite threshold
        above every fault-free flight can be read from it."""
    from scipy import stats  # ~0.5 s to import: only where a Gumbel law is fitted

    maxima = np.asarray(maxima, dtype=float)
    if not np.isfinite(maxima).all():
        raise CalibrationError(f"per-flight maxima {maxima.tolist()} are not all finite")
    q1, q2, q3 = np.quantile(maxima, [0.25, 0.5, 0.75])
    cap = q2 + (q3 - q1) * (_gumbel_unit(CAP_LEVEL) - _gumbel_unit(0.5)) / (
        _gumbel_unit(0.75) - _gumbel_unit(0.25))
    capped = np.minimum(maxima, cap)
    if _flat(capped.min(), capped.max()):
        raise CalibrationError(f"the {maxima.size} per-flight maxima are all "
                               f"{float(capped[0]):g} once capped: a score that does not "
                               "vary between fault-free flights gives no extreme-value "
                               "threshold")
    loc, scale = stats.gumbel_r.fit(capped)
    gamma = float(stats.gumbel_r.ppf(level, loc, scale))
    if not math.isfinite(gamma):
        raise CalibrationError(f"the Gumbel law of maxima {maxima.tolist()} gives no finite "
                               f"threshold at level {level}")
    return gamma


def _weighted_quantile(x: np.ndarray, cum: np.ndarray, m: np.ndarray, p: float) -> np.ndarray:
    """Per row, ``np.quantile`` (linear) of the sorted ``x`` repeated as the row's counts
    say (``cum``: their cumulative sums, ``m``: their totals)."""
    h = (m - 1) * p
    lo = np.floor(h)
    at = (cum <= lo[:, None]).sum(axis=1)                       # repeated index lo
    above = (cum <= np.minimum(lo + 1, m - 1)[:, None]).sum(axis=1)
    return x[at] + (h - lo) * (x[above] - x[at])


def gumbel_thresholds(maxima: np.ndarray, counts: np.ndarray, level: float) -> np.ndarray:
    r""":func:`gumbel_threshold` of many pools at once: pool :math:`b` holds maxima
    :math:`x_i` ``counts[b, i]`` times (a bootstrap of the flights). Each pool's maxima
    are capped as there, and the Gumbel law fitted by maximum likelihood, the scale
    :math:`\beta` by Newton's method on

    .. math::

        \beta = \bar y - \frac{\sum_i w_i y_i e^{-y_i/\beta}}{\sum_i w_i e^{-y_i/\beta}},
        \qquad \mu = -\beta \ln \frac{\sum_i w_i e^{-y_i/\beta}}{\sum_i w_i},

    the equations scipy's ``gumbel_r.fit`` solves one pool at a time (a thousand
    times slower). NaN for a pool of fewer than :data:`MIN_SEGMENTS` maxima, and for
    one whose capped maxima do not vary (where :func:`gumbel_threshold` refuses).

    Raises
    ------
    CalibrationError
        Where the maxima themselves do not vary (or are not finite), as
        :func:`gumbel_threshold` does: then no pool can be fitted."""
    order = np.argsort(maxima)
    x = np.asarray(maxima, dtype=float)[order]
    if x.size and (not np.isfinite(x).all() or _flat(x[0], x[-1])):
        raise CalibrationError(f"the {x.size} per-flight maxima are not finite or do not "
                               "vary: no pool of them gives an extreme-value threshold")
    w = np.asarray(counts, dtype=float)[:, order]
    cum, m = np.cumsum(w, axis=1), w.sum(axis=1)
    ok = m >= MIN_SEGMENTS
    out = np.full(w.shape[0], np.nan)
    if not ok.any() or x.size == 0:
        return out
    w, cum, m = w[ok], cum[ok], m[ok]
    q1, q2, q3 = (_weighted_quantile(x, cum, m, p) for p in (0.25, 0.5, 0.75))
    cap = q2 + (q3 - q1) * (_gumbel_unit(CAP_LEVEL) - _gumbel_unit(0.5)) / (
        _gumbel_unit(0.75) - _gumbel_unit(0.25))
    y = np.minimum(x[None, :], cap[:, None])
    low = y.min(axis=1, keepdims=True)
    mean = (w * y).sum(axis=1) / m
    spread = np.sqrt(np.maximum((w * (y - mean[:, None]) ** 2).sum(axis=1) / m, 1e-24))
    beta = spread * math.sqrt(6.0) / math.pi                    # the moments' estimate
    with np.errstate(invalid="ignore", divide="ignore", over="ignore", under="ignore"):
        for _ in range(60):
            e = w * np.exp(-(y - low) / beta[:, None])
            d0, d1, d2 = e.sum(axis=1), (e * y).sum(axis=1), (e * y * y).sum(axis=1)
            tilted = d1 / d0
            f = mean - beta - tilted                            # MLE equation of beta
            slope = -1.0 - (d2 / d0 - tilted ** 2) / beta ** 2
            beta = np.maximum(beta - f / slope, 1e-12)
        e = w * np.exp(-(y - low) / beta[:, None])
        gamma = low[:, 0] - beta * np.log(e.sum(axis=1) / m) + beta * _gumbel_unit(level)
    # a pool whose capped maxima do not vary has no law to fit, as gumbel_threshold says
    flat = _flat(np.where(w > 0, y, np.inf).min(axis=1), np.where(w > 0, y, -np.inf).max(axis=1))
    flat |= ~np.isfinite(gamma)
    out[ok] = np.where(flat, np.nan, gamma)
    return out


class MaximaThresholds:
    r"""Per-channel thresholds from per-flight maxima (module docstring), for a
    :class:`~.base.Detector` with a ``false_alarm`` hyper-parameter :math:`\alpha`:
    ``class Mine(MaximaThresholds, Detector)``.

    The author writes the scoring (:meth:`~.base.Detector.update`, or a batch
    :meth:`~.base.Detector.run`) and, where the scores need a model, :meth:`fit_model`;
    :meth:`fit` fits the model, scores every fault-free segment and thresholds the
    maxima. A channel's maxima come from the segments on which it scores at all.

    Attributes
    ----------
    maxima_ : dict of str to list of float
        Per channel, :math:`M_{c,j}` over the training segments.
    gamma_ : dict of str to float
        Per channel, :math:`\gamma_c`.
    maxima_flights_ : dict of str to list of str
        Per channel, the flight of each of ``maxima_`` (:meth:`pool_thresholds`).
    model_ : tuple of str
        The attributes :meth:`fit_model` learned (reported by :meth:`fitted`).
    """

    calibrated = True
    threshold_params = ("false_alarm",)

    def fit_model(self, segments) -> MaximaThresholds:
        """Learn what the scores need from fault-free ``segments``; return self.
        Nothing by default."""
        return self

    def fit(self, segments) -> MaximaThresholds:
        """:meth:`fit_model`, then the maxima of the scores of ``segments`` and
        :meth:`rethreshold`."""
        self.fit_model(segments)
        # a fit starts from no learned attribute (Detector.fit): these are the model's
        self.model_ = tuple(learned_state(self))
        self.maxima_, self.maxima_flights_ = self.segment_maxima(segments)
        return self.rethreshold()

    def fit_out_of_sample(self, segments, splits) -> MaximaThresholds:
        """:meth:`fit` with maxima out of sample: per ``(training, held)`` of ``splits``,
        the model fitted on ``training`` gives the maxima of the ``held`` segments (a
        model may score its own training data low); then the model is fitted on every
        one of ``segments``, and the thresholds set. A model a subclass fits this way
        is its own to report in :meth:`fitted` (``model_`` is empty)."""
        maxima = {c: [] for c in self.channels()}
        flights = {c: [] for c in self.channels()}
        for training, held in splits:
            self.fit_model(training)
            got, of = self.segment_maxima(held)
            for c in maxima:
                maxima[c] += got[c]
                flights[c] += of[c]
        self.fit_model(segments)
        self.model_ = ()
        self.maxima_, self.maxima_flights_ = maxima, flights
        return self.rethreshold()

    def segment_maxima(self, segments) -> tuple[dict, dict]:
        """Per channel, the maxima of the current model's scores over ``segments`` and
        the flight of each (a segment on which the channel never scores gives none)."""
        maxima = {c: [] for c in self.channels()}
        flights = {c: [] for c in self.channels()}
        # in one run_many: a model that costs more a call than a row scores them at once
        with np.errstate(invalid="ignore"):
            scored = self.run_many([(s, 0, None) for s in segments])
        for s, (score, _) in zip(segments, scored, strict=True):
            for c, column in zip(maxima, score.T, strict=True):
                if np.isfinite(column).any():
                    maxima[c].append(float(np.nanmax(column)))
                    flights[c].append(s.flight)
        return maxima, flights

    def rethreshold(self) -> MaximaThresholds:
        """:math:`\\gamma_c` from the fitted maxima, for ``false_alarm``; return self.

        Raises
        ------
        CalibrationError
            Where a channel has fewer than :data:`MIN_SEGMENTS` maxima."""
        self.__dict__.pop("gamma_", None)
        level = 1.0 - self.false_alarm / len(self.maxima_)
        gamma = {}
        for name, maxima in self.maxima_.items():
            if len(maxima) < MIN_SEGMENTS:
                raise CalibrationError(
                    f"{type(self).__name__}: channel {name!r} has per-flight maxima from "
                    f"{len(maxima)} fault-free segments long enough to score; the "
                    f"extreme-value threshold needs at least {MIN_SEGMENTS}")
            gamma[name] = max(gumbel_threshold(maxima, level), 1e-9)
        self.gamma_ = gamma
        return self

    def thresholds(self) -> np.ndarray:
        self._check_fitted("gamma_")
        return np.array([self.gamma_[c] for c in self.channels()])

    def pool_thresholds(self, pools: list[dict[str, int]]) -> np.ndarray:
        """Per pool (flight -> how many times it was drawn) and channel, the threshold
        from the maxima of the flights drawn: the bootstrap of :meth:`fit`'s
        thresholds, all else it learned kept. Shape (pools, channels); NaN where a
        pool holds too few maxima of a channel."""
        self._check_fitted("gamma_")
        level = 1.0 - self.false_alarm / len(self.maxima_)
        out = np.empty((len(pools), len(self.maxima_)))
        for j, c in enumerate(self.channels()):
            counts = np.array([[pool.get(f, 0) for f in self.maxima_flights_[c]]
                               for pool in pools])
            out[:, j] = np.maximum(gumbel_thresholds(np.array(self.maxima_[c]), counts,
                                                     level), 1e-9)
        return out

    def fitted(self) -> dict:
        """The maxima and the thresholds, per channel, and what :meth:`fit_model`
        learned (``model``, where it learned anything)."""
        self._check_fitted("gamma_")
        model = {n: json_ready(getattr(self, n)) for n in self.model_}
        return {"segment_maxima": self.maxima_, "gamma": self.gamma_,
                **({"model": model} if model else {})}
