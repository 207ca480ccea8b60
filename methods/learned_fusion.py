r"""Learned fusion: a Gaussian mixture density over the residual bank's steps.

The hand-made fusion of :mod:`.residual_bank` thresholds each channel on its own and
alarms when any channel does. This baseline learns the fusion instead: the vector of
the bank's steps :math:`\mathbf d(t) = [d_1(t), \dots, d_C(t)]` (eq. 2 there, signed)
is scored by its negative log-density under a Gaussian mixture (scikit-learn's
:class:`~sklearn.mixture.GaussianMixture`) fitted to fault-free steps only,

.. math::

    s(t) = -\log \sum_{i=1}^{K} w_i\,
           \mathcal N(\mathbf d(t);\ \boldsymbol\mu_i, \Sigma_i)               (1)

Joint patterns that no channel shows alone (a small step in thrust with a small one
in pitch, against their fault-free correlation) can score high. The number of
components :math:`K \le` ``max_components`` is chosen on the training data by the
Bayesian information criterion, so it too comes from fault-free data. The fit uses
every ``thin``-th step: steps 1/20 s apart over a 1 s window are nearly the same
point.

An isolation forest was the first choice and is not used: its score saturates (on
the synthetic flights of the tests, a single-channel step of 14 fault-free standard
deviations scored 0.61 while fault-free per-flight maxima reached 0.65), so it could
not tell a large fault from an ordinary flight's worst moment.

Training sees what every calibrated method sees: fault-free flights and the parts of
the others before onset, leaving out the day scored. There are no fault examples to
train on, so the model is one-class; a classifier (logistic regression, boosting)
would need faulty training data the protocol does not give. The threshold is read as
the bank's are: a Gumbel law fitted to the per-flight maxima of :math:`s` on the
training segments, at :math:`1 - \alpha`.

The fused channel does not say which sensor moved. It reports the thrust model's
output, :math:`a_x`, so its isolation rows name the engine for every detection: read
them as detection only.
"""

from __future__ import annotations

import math

import numpy as np

from alfa_bench.data import Sampled

from .base import CalibrationError, Detector
from .extremes import MaximaThresholds
from .residual_bank import DEFAULT_MODELS, ResidualBank

__all__ = ["LearnedFusion"]


class LearnedFusion(MaximaThresholds, Detector):
    """A Gaussian mixture density (1) over the steps of a
    :class:`~.residual_bank.ResidualBank`.

    Parameters
    ----------
    models, lags_s, window_s, baseline_s, rate_hz
        Those of the underlying :class:`~.residual_bank.ResidualBank`.
    max_components : int
        The largest :math:`K` tried.
    thin : int
        Every ``thin``-th fault-free step is used to fit the mixture.
    false_alarm : float
        :math:`\\alpha`: the probability that a fault-free flight alarms.
    random_state : int
        Seed of the mixture's initialisation: the same seed, the same mixture.

    Attributes
    ----------
    bank_ : ResidualBank
        Its models (1) fitted on the training segments (only its steps are used).
    mixture_ : GaussianMixture
        The mixture of the chosen :math:`K`.
    bic_ : list of float
        BIC per :math:`K` tried.
    maxima_, gamma_ : dict
        Per-segment maxima of :math:`s` and the threshold
        (:class:`~.extremes.MaximaThresholds`).
    """

    family = "model residuals"

    def __init__(self, models=DEFAULT_MODELS, lags_s=(0.0, 0.5, 1.0, 2.0), window_s=1.0,
                 baseline_s=20.0, max_components=6, thin=5, false_alarm=0.1, random_state=0,
                 rate_hz=20.0):
        self.models = models
        self.lags_s = lags_s
        self.window_s = window_s
        self.baseline_s = baseline_s
        self.max_components = max_components
        self.thin = thin
        self.false_alarm = false_alarm
        self.random_state = random_state
        self.rate_hz = rate_hz

    def _bank(self) -> ResidualBank:
        return ResidualBank(models=self.models, lags_s=self.lags_s, window_s=self.window_s,
                            baseline_s=self.baseline_s, false_alarm=self.false_alarm,
                            rate_hz=self.rate_hz)

    def signals(self) -> tuple[str, ...]:
        return self._bank().signals()

    def channels(self) -> tuple[str, ...]:
        return ("fused",)

    def channel_outputs(self) -> tuple[str, ...]:
        return (self.models[0]["output"],)

    def _anomaly(self, d: np.ndarray) -> np.ndarray:
        """:math:`s` of (1) per row of steps ``d``; NaN where a step is not yet defined."""
        s = np.full(d.shape[0], np.nan)
        ok = np.isfinite(d).all(axis=1)
        if ok.any():
            with np.errstate(under="ignore"):     # exp of far-away components: 0 is right
                s[ok] = -self.mixture_.score_samples(d[ok])                  # (1)
        return s

    def fit_model(self, segments: list[Sampled]) -> LearnedFusion:
        """The bank's models, and the mixture of the chosen :math:`K` on their
        fault-free steps; the threshold comes from
        :class:`~.extremes.MaximaThresholds`."""
        self.__dict__.pop("mixture_", None)
        self.bank_ = self._bank().fit_models(segments)
        steps = [self.bank_.steps(self.bank_.residuals(s)[1]) for s in segments]
        rows = np.vstack([d[np.isfinite(d).all(axis=1)] for d in steps])
        if rows.shape[0] == 0:
            raise CalibrationError("learned fusion: no fault-free segment is long enough "
                                   f"to score ({self.window_s + self.baseline_s} s)")
        rows = rows[::self.thin]
        # imported here: every job imports the registry, only this method needs it
        from sklearn.mixture import GaussianMixture

        fits = [GaussianMixture(k, random_state=self.random_state).fit(rows)
                for k in range(1, self.max_components + 1)]
        self.bic_ = [float(m.bic(rows)) for m in fits]
        self.mixture_ = fits[int(np.argmin(self.bic_))]
        return self

    def fitted(self) -> dict:
        self._check_fitted("gamma_")
        return {"bank": {n: {"theta": t.tolist(), "sigma": self.bank_.sigma_[n]}
                         for n, t in self.bank_.theta_.items()},
                "mixture": {"components": int(self.mixture_.n_components), "bic": self.bic_,
                            "weights": self.mixture_.weights_.tolist()},
                "segment_maxima": self.maxima_["fused"], "gamma": self.gamma_["fused"]}

    def reset(self) -> LearnedFusion:
        self._check_fitted("mixture_")
        self.bank_.reset()
        self.last_ = math.nan
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        self.bank_.update(x, fresh)
        self.last_ = float(self._anomaly(self.bank_.last_["step"][None, :])[0])
        return np.array([self.last_])

    def probes(self) -> dict[str, float]:
        last = getattr(self, "bank_", None)
        steps = last.last_["step"] if last is not None and hasattr(last, "last_") else None
        return {f"{m['name']}/step": (float(steps[c]) if steps is not None else math.nan)
                for c, m in enumerate(self.models)}

    def snapshot(self) -> dict:
        """Nothing: the bank's steps depend on its last
        :meth:`~.residual_bank.ResidualBank.memory_steps` steps only."""
        return {}

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: dict | None = None) -> tuple[np.ndarray, dict]:
        """The batch form of :meth:`update` over ``s`` (equal to rounding); continued
        from step ``start`` as the bank's run is."""
        self.reset()
        start = 0 if state is None else start
        first = max(0, start - self.bank_.memory_steps())
        d = self.bank_.steps(self.bank_.residuals(s.since(first))[1])[start - first:]
        score = self._anomaly(d)[:, None]
        kept = ({f"{m['name']}/step": d[:, c] for c, m in enumerate(self.models)}
                if probes else {})
        return score, kept
