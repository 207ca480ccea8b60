r"""alfa-bench's own supervised entry: a logistic regression on every physical feature
the project computes.

:mod:`.residual_logistic` reproduces a public study's classifier on its 25 residual
features. This one keeps its score, persistence, warm-up, positives and thresholds
(eq. 3 there, and out-of-sample fault-free per-flight maxima) and widens what it
reads to the union of three blocks of causal features, each on the 10 Hz grid:

``study``
    the study's 25: five linear residuals :math:`z_c` and their trailing statistics
    (:func:`~.residual_logistic.residual_features`);
``bank``
    the steps :math:`d_c` of :mod:`.residual_bank` (its eq. 2: a residual's 1 s mean
    against its 20 s baseline, in units of its fault-free spread) of its five models,
    signed and absolute:

    .. math:: \mathbf f_{bank}(k) = [d_1(k), \dots, d_5(k), |d_1(k)|, \dots, |d_5(k)|]

``physics``
    the ten signatures of :mod:`.physics` that :mod:`.coincidence` combines (steps of
    the specific force, the energy and climb rates, the pitch shortfall, the
    attitude loops' gains, the roll asymmetry, ...), fitted on nothing.

A bank step or signature is not defined before its windows fill (about 23 s) or while
they hold no fresh sample; it reads 0 there, "no step", so that the study's 15 s
warm-up stays the one that counts. ``features`` names the blocks the regression reads
(the study's always among them); the detector reads the signals of all three, so that
every choice of blocks reads the same inputs and a nested selection may choose among
them. The bank's models and the study's residuals are fitted, as the regression, on
the training flights only: the bank's on their steps before onset.

The configured runs choose the blocks and :math:`C` by the inner leave-one-date-out of
:mod:`.nested_selection`, positives as the study's (``all``) or without the
emergency-trajectory flights (``no_emr``). Like the study's classifier it reports one
channel, :math:`a_x`'s: read its isolation rows as detection only.
"""

from __future__ import annotations

import math
import weakref
from collections import deque

import numpy as np

from alfa_bench.data import Sampled

from . import physics
from .base import Labelled
from .fits import kept_fit
from .residual_bank import ResidualBank
from .residual_logistic import (
    INPUTS,
    LONGEST_WINDOW_S,
    WARMUP_S,
    ResidualLogistic,
    residual_features,
    residuals,
)
from .windows import window_steps

__all__ = ["BLOCKS", "BenchLogistic"]

#: the feature blocks a :class:`BenchLogistic` may read (module docstring)
BLOCKS = ("study", "bank", "physics")


class BenchLogistic(ResidualLogistic):
    """The study's logistic score (3) of :mod:`.residual_logistic` on the union of the
    project's feature blocks (module docstring), thresholds from out-of-sample
    fault-free per-flight maxima.

    Parameters
    ----------
    features : tuple of str
        The blocks of :data:`BLOCKS` the regression reads; ``"study"`` among them.
    positives, C, persist, warmup_s, margin_s, false_alarm
        As :class:`~.residual_logistic.ResidualLogistic`'s.

    Attributes
    ----------
    bank_ : ResidualBank
        The bank's models, fitted on the training flights before onset (``bank`` read).
    weights_, sigma_, center_, scale_, coef_, intercept_
        As :class:`~.residual_logistic.ResidualLogistic`'s, over the blocks read.
    """

    #: the physical signatures' grid: the blocks share it
    rate_hz = physics.RATE_HZ

    def __init__(self, features=BLOCKS, positives="all", C=0.1, persist=5, warmup_s=WARMUP_S,
                 margin_s=1.0, false_alarm=0.1):
        self.features = features
        self.positives = positives
        self.C = C
        self.persist = persist
        self.warmup_s = warmup_s
        self.margin_s = margin_s
        self.false_alarm = false_alarm

    def _bank(self) -> ResidualBank:
        return ResidualBank(rate_hz=self.rate_hz)

    def _blocks(self) -> tuple[str, ...]:
        blocks = tuple(self.features)
        if "study" not in blocks or not set(blocks) <= set(BLOCKS) or len(set(blocks)) < len(
                blocks):
            raise ValueError(f"features must name distinct blocks of {BLOCKS}, 'study' among "
                             f"them; got {self.features!r}")
        return blocks

    def signals(self) -> tuple[str, ...]:
        read = (*INPUTS, *self._bank().signals(), *physics.SIGNALS_READ)
        return tuple(dict.fromkeys(read))

    def _fit_features(self, free: list[Sampled]) -> None:
        """The study's residual models, and the bank's where it is read, on the
        training flights' parts before onset."""
        super()._fit_features([s.columns(INPUTS) for s in free])
        if "bank" in self._blocks():
            bank = self._bank()
            self.bank_ = bank.fit_models([s.columns(bank.signals()) for s in free])

    def _features(self, s: Sampled, first_step: int = 0) -> np.ndarray:
        blocks = self._blocks()
        out = [residual_features(residuals(s.columns(INPUTS).x, self.weights_, self.sigma_),
                                 self.rate_hz)]
        if "bank" in blocks:
            d = self.bank_.steps(self.bank_.residuals(s.columns(self.bank_.signals()))[1])
            out += [_undefined_as_zero(d), _undefined_as_zero(np.abs(d))]
        if "physics" in blocks:
            out.append(_physics_block(s, first_step))
        return np.hstack(out)

    def _history(self) -> int:
        """The steps a step's features read: the longest window of any block."""
        return max(window_steps(physics.HISTORY_S, self.rate_hz),
                   self._bank().memory_steps() + 1,
                   window_steps(LONGEST_WINDOW_S, self.rate_hz))

    def _lookback(self) -> int:
        return self._history() + self.persist

    feature_state = ("weights_", "sigma_", "bank_")
    #: what :meth:`fit_model` learns
    model_state = ("weights_", "sigma_", "bank_", "center_", "scale_", "coef_", "intercept_")

    def fit_model(self, segments: list[Labelled]) -> BenchLogistic:
        """The study's fit over the blocks read, or the same fit from
        :data:`~.fits.MODEL_FITS` (:func:`~.fits.kept_fit`): a nested selection asks for
        each candidate's fit without the same dates again and again."""
        kept_fit(self, segments, super().fit_model, self.model_state)
        return self

    def reset(self) -> BenchLogistic:
        self._check_fitted("coef_")
        self.history_ = {"x": deque(maxlen=self._history()),
                         "fresh": deque(maxlen=self._history())}
        self.logits_ = deque(maxlen=self.persist)
        self.step_ = 0
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        h = self.history_
        h["x"].append(np.asarray(x, dtype=float))
        h["fresh"].append(np.asarray(fresh, dtype=bool))
        self.step_ += 1
        n = len(h["x"])
        s = Sampled(t=np.arange(n) / self.rate_hz, x=np.array(h["x"]),
                    fresh=np.array(h["fresh"]), names=self.signals())
        # the batch's features of the stream's last step, from its recent past
        f = self._features(s, first_step=self.step_ - n)[-1]
        self.logits_.append(float(((f - self.center_) / self.scale_) @ self.coef_
                                  + self.intercept_))
        armed = len(self.logits_) == self.persist and self.step_ > self._steps(self.warmup_s)
        low = float(np.min(self.logits_)) if armed else math.nan            # m of (3)
        with np.errstate(under="ignore"):
            return np.array([np.logaddexp(0.0, low) if math.isfinite(low) else math.nan])

    def _model_report(self) -> dict:
        report = super()._model_report()
        if "bank" in self._blocks():
            report["bank"] = {n: {"theta": t.tolist(), "sigma": self.bank_.sigma_[n]}
                              for n, t in self.bank_.theta_.items()}
        return report


#: the physics block of each segment still alive, by ``id``: (a reference that tells
#: the segment is the one keyed, first step, block)
_PHYSICS: dict[int, tuple[weakref.ref, int, np.ndarray]] = {}


def _physics_block(s: Sampled, first_step: int) -> np.ndarray:
    """The physics block of ``s``, computed once per segment: it is fitted on nothing, so
    that every candidate and fold of a nested selection reads the same block of the same
    segment (a tenth of its job when computed for each). Read-only: every caller shares
    it."""
    kept = _PHYSICS.get(id(s))
    if kept is not None and kept[0]() is s and kept[1] == first_step:
        return kept[2]
    feats = physics.features_of(s.columns(physics.SIGNALS_READ), first_step)
    block = _undefined_as_zero(np.column_stack([feats[f] for f in physics.FEATURES]))
    block.flags.writeable = False
    key = id(s)
    _PHYSICS[key] = (weakref.ref(s, lambda _: _PHYSICS.pop(key, None)), first_step, block)
    return block


def _undefined_as_zero(f: np.ndarray) -> np.ndarray:
    """A step or signature not yet defined (NaN) read as no step."""
    return np.where(np.isnan(f), 0.0, f)
