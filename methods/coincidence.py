r"""Faults as a coincidence of physical signatures.

Each channel :math:`c` names a set :math:`F_c` of the features of :mod:`.physics`
(causal steps of the specific force, the energy rate, the climb rate, the pitch
against its command, ...). Each feature :math:`f` is scaled by :math:`\sigma_f`, the
``quantile`` of its values over the fault-free training data, and the channel scores
the least of its scaled features:

.. math::

    s_c(t) = \min_{f \in F_c} f(t) / \sigma_f                                  (1)

so it rises only while every signature of its set is present at once. A lost engine
drops the specific force and the energy rate and leaves the nose below its command,
all together and for as long as the engine is out; a manoeuvre or a gust makes one or
two of them (a dive drops the climb rate but raises the speed, a pull-up raises the
pitch error with the energy), and seldom all. A set of one feature is that feature
alone (the lateral force of a stuck rudder).

Thresholds count false alarms per flight, as the residual bank's do (eq. 3 of
:mod:`.residual_bank`): the per-segment maxima of :math:`s_c` over the fault-free
training segments are fitted with a capped Gumbel law and

.. math::

    \gamma_c = F^{-1}_{\mathrm{Gumbel}}(1 - \alpha / C)                       (2)

for :math:`C` channels, so that a fault-free flight like the training ones alarms with
probability about :math:`\alpha` (``false_alarm``).

The default signatures are argued from the physics, before any score: ``engine`` takes
every engine signature of :data:`~.physics.FEATURES` (the energy loss seen four ways),
``side`` the lateral force (a stuck rudder sideslips). Which engine signatures to
require together is a hyper-parameter; ``coincidence_nested`` in the config chooses it
per scored date by the inner leave-one-date-out of :mod:`.nested_selection`.
Streaming (:meth:`Coincidence.update`) recomputes the features over the stream's last
:data:`~.physics.HISTORY_S`, which every window fits in, so it equals the batch form
to rounding.
"""

from __future__ import annotations

import math

import numpy as np

from alfa_bench.data import Sampled

from .base import CalibrationError, Detector
from .extremes import MaximaThresholds
from .physics import FEATURE_SIGNAL, FEATURES, HISTORY_S, RATE_HZ, SIGNALS_READ, features_of
from .windows import window_steps

__all__ = ["Coincidence", "DEFAULT_SIGNATURES"]

#: channel -> the features it requires at once (module docstring)
DEFAULT_SIGNATURES = {
    "engine": ["accel_x_drop", "energy_rate_drop", "climb_rate_drop", "pitch_shortfall"],
    "side": ["accel_y_shift"],
}


class Coincidence(MaximaThresholds, Detector):
    """Channels of coinciding physical signatures (1), with per-flight thresholds (2).

    Parameters
    ----------
    signatures : dict of str to list of str
        Per channel (its name), the features of :data:`~.physics.FEATURES` it requires at once.
    quantile : float
        The fault-free quantile that scales each feature.
    false_alarm : float
        :math:`\\alpha`: the probability that a fault-free flight alarms on any channel.

    Attributes
    ----------
    scale_ : dict
        :math:`\\sigma_f` per feature used.
    maxima_, gamma_ : dict
        Per channel, the per-segment maxima of its score over the training segments
        and :math:`\\gamma_c` (:class:`~.extremes.MaximaThresholds`).
    """

    family = "model residuals"

    rate_hz = RATE_HZ

    def __init__(self, signatures=DEFAULT_SIGNATURES, quantile=0.99, false_alarm=0.1):
        self.signatures = signatures
        self.quantile = quantile
        self.false_alarm = false_alarm

    def signals(self) -> tuple[str, ...]:
        return SIGNALS_READ

    def channels(self) -> tuple[str, ...]:
        return tuple(self.signatures)

    def channel_outputs(self) -> tuple[str, ...]:
        return tuple(FEATURE_SIGNAL[fs[0]] for fs in self._sets())

    def _sets(self) -> list[list[str]]:
        sets = list(self.signatures.values())
        unknown = sorted({f for fs in sets for f in fs} - set(FEATURES))
        if unknown or not all(sets):
            raise ValueError(f"coincidence channels need features of {sorted(FEATURES)}; "
                             f"got {self.signatures}")
        return sets

    def _scores(self, feats: dict[str, np.ndarray]) -> np.ndarray:
        with np.errstate(invalid="ignore"):
            return np.column_stack([
                np.min(np.vstack([feats[f] / self.scale_[f] for f in fs]), axis=0)
                for fs in self._sets()])                              # (1)

    def fit_model(self, segments: list[Sampled]) -> Coincidence:
        """:math:`\\sigma_f` of (1) for every feature used; the thresholds (2) come
        from :class:`~.extremes.MaximaThresholds`."""
        self.__dict__.pop("scale_", None)
        used = sorted({f for fs in self._sets() for f in fs})
        feats = [features_of(s) for s in segments]
        scale = {}
        for f in used:
            values = np.concatenate([v[f][np.isfinite(v[f])] for v in feats])
            if values.size == 0:
                raise CalibrationError(f"feature {f!r} is never computed on the fault-free "
                                       "data")
            scale[f] = float(np.quantile(values, self.quantile))
            if not scale[f] > 0:
                raise CalibrationError(f"feature {f!r} has a fault-free {self.quantile} "
                                       f"quantile of {scale[f]}: nothing to scale by")
        self.scale_ = scale
        return self

    def fitted(self) -> dict:
        self._check_fitted("gamma_")
        return {"scale": self.scale_, "segment_maxima": self.maxima_,
                "gamma": self.thresholds().tolist()}

    def probes(self) -> dict[str, float]:
        last = getattr(self, "last_", {})
        return {f"{c}/{f}": float(last.get(f, math.nan)) / self.scale_[f]
                if hasattr(self, "scale_") else math.nan
                for c, fs in zip(self.channels(), self._sets(), strict=True) for f in fs}

    def reset(self) -> Coincidence:
        self._check_fitted("scale_")
        self.history_ = {"x": [], "fresh": []}
        self.steps_ = 0
        self.last_ = {}
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        h, keep = self.history_, window_steps(HISTORY_S, RATE_HZ)
        h["x"].append(np.asarray(x, dtype=float))
        h["fresh"].append(np.asarray(fresh, dtype=bool))
        del h["x"][:-keep], h["fresh"][:-keep]
        self.steps_ += 1
        n = len(h["x"])
        s = Sampled(t=np.arange(n) / RATE_HZ, x=np.array(h["x"]), fresh=np.array(h["fresh"]),
                    names=self.signals())
        feats = features_of(s, first_step=self.steps_ - n)
        self.last_ = {f: v[-1] for f, v in feats.items()}
        return self._scores({f: v[-1:] for f, v in feats.items()})[0]

    def snapshot(self) -> dict:
        """Nothing: every feature's windows fit in the last :data:`~.physics.HISTORY_S`,
        which a continued :meth:`run` reads again from its segment."""
        return {}

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: dict | None = None) -> tuple[np.ndarray, dict]:
        """The batch form of :meth:`update` over ``s`` (equal to rounding); continued
        from step ``start`` (any ``state``), it runs from :data:`~.physics.HISTORY_S`
        before."""
        self.reset()
        start = 0 if state is None else start
        first = max(0, start - window_steps(HISTORY_S, RATE_HZ))
        feats = {f: v[start - first:]
                 for f, v in features_of(s.since(first), first_step=first).items()}
        kept = ({f"{c}/{f}": feats[f] / self.scale_[f]
                 for c, fs in zip(self.channels(), self._sets(), strict=True) for f in fs}
                if probes else {})
        self.steps_ = s.t.size
        return self._scores(feats), kept
