r"""A public ALFA study's classifier: logistic regression on physical residuals.

The public study ``bvsrasen/alfa-fault-detection`` (GitHub; results in its
``docs/sonuclar.md``) detects ALFA's faults with a logistic regression over five
linear residual channels. This module reproduces it from the facts its repository
states, and runs the same model under this project's protocol.

**Residuals.** On a 10 Hz zero-order-hold grid, with the autopilot's velocity
estimate :math:`V = \lVert \mathbf v \rVert` (``nav_info``), the attitude errors
:math:`e_\phi = \phi_{cmd} - \phi`, :math:`e_\theta = \theta_{cmd} - \theta` (deg),
the altitude error :math:`e_h` (m) and the airspeed error :math:`e_V` (m/s), each
target is regressed with an intercept on

.. math::

    a_x &\sim 1 + e_h + e_V + \theta, \qquad a_y \sim 1, \qquad
    p \sim 1 + e_\phi, \\
    q &\sim 1 + e_\theta + \phi^2, \qquad
    r \sim 1 + g \tan\phi / \max(V, 5\ \mathrm{m/s})                          (1)

by least squares over the *nominal* steps of the training flights (after the
warm-up, before onset), and its residual is divided by the nominal residuals'
standard deviation:

.. math::

    z_c(k) = \big(y_c(k) - \mathbf x_c(k)^\top \mathbf w_c\big) / \sigma_c    (2)

**Features.** Per channel, :math:`z`, :math:`|z|`, the 1 s and 3 s trailing means of
:math:`z` (over the steps there are, at the start of a run) and its 1 s trailing
standard deviation (ddof 1; 0 over one step): 25 features, standardised by the
training steps' mean and standard deviation, :math:`\mathbf f(k)`.

**Score.** A logistic regression (scikit-learn, :math:`C = 0.1`, balanced classes,
label 1 from onset on) fitted on the training flights' steps after the warm-up gives
the logit :math:`\ell(k) = b + \boldsymbol\beta^\top \mathbf f(k)`; an alarm needs it
high for :math:`n = 5` steps (0.5 s), and none comes in the warm-up (the first 15 s
of a run):

.. math::

    s(k) = \log\big(1 + e^{m(k)}\big), \qquad
    m(k) = \min_{k - n < j \le k} \ell(j)                                       (3)

The study thresholds :math:`m` itself; (3) is :math:`-\ln(1 - p)` of its fault
probability, the same alarms at the matching threshold, and positive, as this
project's thresholds are (a threshold scale multiplies it).

**Thresholds.**

- :class:`ResidualLogisticPublished`, the study's rule: the training flights are
  scored in sample, and the threshold is the middle of the first interval of
  thresholds that maximises their per-flight accuracy by the paper's rule (an alarm
  before onset or on a fault-free flight a false positive; any later alarm on a
  faulty flight a detection, however late).
- :class:`ResidualLogistic`, this project's: per-flight maxima of :math:`s` over the
  fault-free segments (fault-free flights, faulty ones up to ``margin_s`` before
  onset; :class:`~.extremes.MaximaThresholds`), each scored out of sample by the
  model fitted without the flight's date (an inner leave-one-date-out over the
  training dates), so that pools and survival apply.

**Positives.** ``positives="all"`` learns label 1 from every faulty training flight,
as the study does; ``"no_emr"`` not from the flights that switch to an emergency
trajectory at onset (their commands change because of the label), whose steps
before onset stay negatives.

The warm-up counts grid steps from the start of the run, so that a streamed and a
batch run agree; the study counts it from the first ``nav_info-roll`` row (within a
second of it in ALFA). The one channel reports :math:`a_x`: read its isolation rows
as detection only.
"""

from __future__ import annotations

import contextlib
import math
from collections import deque

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from alfa_bench.data import Sampled

from .base import (
    CalibrationError,
    Detector,
    Labelled,
    StaleStateError,
    fit_token,
    free_part,
    json_ready,
    leave_one_date_out,
)
from .extremes import MaximaThresholds
from .fits import KeptFits, fit_key, segments_data
from .windows import window_steps

__all__ = ["CHANNELS", "DESIGNS", "INPUTS", "LONGEST_WINDOW_S", "WARMUP_S", "ResidualLogistic",
           "ResidualLogisticPublished", "best_accuracy_threshold", "fit_residuals",
           "residual_features", "residuals"]

#: standard gravity, m/s^2
G = 9.80665

#: the signals read, in this order
INPUTS = ("accel_x", "accel_y", "roll_rate", "pitch_rate", "yaw_rate", "roll", "roll_cmd",
          "pitch", "pitch_cmd", "altitude_error", "airspeed_error", "nav_vel_north",
          "nav_vel_east", "nav_vel_down")

#: the study's warm-up, s: no score, and no training step, before it
WARMUP_S = 15.0

#: the longest trailing window of the features, s: what a step's features read
LONGEST_WINDOW_S = 3.0

#: the designs (feature models, features and labels) of the fits
#: :meth:`_ResidualClassifier.fit_model` made in this process, by the code, the
#: hyper-parameters that shape them (all but :math:`C` and the threshold's) and the data
#: (:func:`~.fits.fit_key`): the 8 last used, since a nested selection fits the
#: candidates that share them in turn (each on its inner folds and then whole), and a
#: design holds every training step's features
DESIGNS = KeptFits(8, counted=False)

#: the residual channels (1): target -> regressors (an intercept besides)
CHANNELS = {"accel_x": ("altitude_error", "airspeed_error_ms", "pitch"),
            "accel_y": (),
            "roll_rate": ("roll_error",),
            "pitch_rate": ("pitch_error", "roll_squared"),
            "yaw_rate": ("turn_rate",)}


def _quantities(x: np.ndarray) -> dict[str, np.ndarray]:
    """The columns of ``x`` (shape (n, len(INPUTS))) by name, with the derived ones
    (1) needs."""
    q = dict(zip(INPUTS, x.T, strict=True))
    speed = np.sqrt(q["nav_vel_north"] ** 2 + q["nav_vel_east"] ** 2 + q["nav_vel_down"] ** 2)
    q["roll_error"] = q["roll_cmd"] - q["roll"]
    q["pitch_error"] = q["pitch_cmd"] - q["pitch"]
    q["roll_squared"] = q["roll"] ** 2
    q["turn_rate"] = G * np.tan(np.radians(q["roll"])) / np.maximum(speed, 5.0)
    q["airspeed_error_ms"] = q["airspeed_error"] / 100.0            # logged in cm/s
    return q


def _design(q: dict, regressors: tuple[str, ...]) -> np.ndarray:
    return np.column_stack([np.ones(q["roll"].size), *(q[r] for r in regressors)])


def _trailing(z: np.ndarray, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Per step of ``z`` (n, c), the mean and the standard deviation (ddof 1, 0 over a
    single step) of its last ``w`` steps, or of those there are. Each window is summed
    on its own (``w`` shifted adds, no running sum that a huge value would spoil)."""
    n = z.shape[0]
    count = np.minimum(np.arange(1, n + 1), w)[:, None]
    total = np.zeros_like(z)
    for j in range(min(w, n)):
        total[j:] += z[:n - j]
    mean = total / count
    dev = np.zeros_like(z)
    for j in range(min(w, n)):
        dev[j:] += (z[:n - j] - mean[j:]) ** 2
    return mean, np.where(count > 1, np.sqrt(dev / np.maximum(count - 1, 1)), 0.0)


def fit_residuals(x: np.ndarray) -> tuple[dict, dict]:
    """The residual models (1) fitted by least squares on the nominal rows ``x`` (shape
    (n, len(INPUTS))): per channel its coefficients and the spread of its residuals.

    Raises
    ------
    CalibrationError
        With fewer than 10 rows, or a channel whose residuals do not spread."""
    nom = _quantities(x)
    if nom["roll"].size < 10:
        raise CalibrationError(f"residual models: {nom['roll'].size} nominal steps after "
                               "the warm-up to fit them on")
    weights, sigma = {}, {}
    for y, r in CHANNELS.items():
        X = _design(nom, r)
        w, *_ = np.linalg.lstsq(X, nom[y], rcond=None)                   # (1)
        weights[y] = w
        sigma[y] = float(np.std(nom[y] - X @ w))
        if not sigma[y] > 0:
            raise CalibrationError(f"residual models: channel {y} has no nominal spread "
                                   "to scale by")
    return weights, sigma


def residuals(x: np.ndarray, weights: dict, sigma: dict) -> np.ndarray:
    """:math:`z` (2) of each row of ``x``, shape (n, 5). Each row's arithmetic is its
    own (products summed in a fixed order, no matrix product whose kernel changes with
    the rows), so that a step streamed alone gets the batch's residual bit for bit."""
    q = _quantities(x)
    out = []
    for y, r in CHANNELS.items():
        w = weights[y]
        fit = np.full(q["roll"].size, w[0])
        for name, wj in zip(r, w[1:], strict=True):
            fit = fit + wj * q[name]
        out.append((q[y] - fit) / sigma[y])                                     # (2)
    return np.column_stack(out)


def residual_features(z: np.ndarray, rate_hz: float) -> np.ndarray:
    """The 25 features of each step of the residuals ``z`` (n, 5), over the steps there
    are at the start: :math:`z`, :math:`|z|`, the 1 s and 3 s trailing means and the
    1 s trailing standard deviation."""
    mean_short, std_short = _trailing(z, window_steps(1.0, rate_hz))
    mean_long, _ = _trailing(z, window_steps(LONGEST_WINDOW_S, rate_hz))
    return np.hstack([z, np.abs(z), mean_short, mean_long, std_short])


def best_accuracy_threshold(before: np.ndarray, after: np.ndarray,
                            faulty: np.ndarray) -> float:
    """The study's threshold: per training flight, the largest score before onset
    (``before``; over the whole of a fault-free flight) and from onset on
    (``after``), and whether it is faulty. A threshold :math:`h` gives a false
    positive where ``before > h``, else a detection where faulty and
    ``after > h``, else a true negative where fault-free. Over the finite values of
    both, the first candidate of the best accuracy, and the middle between it and the
    next (or it + 1 at the last)."""
    candidates = np.unique(np.concatenate([before, after]))
    candidates = candidates[np.isfinite(candidates)]
    if candidates.size == 0:
        raise CalibrationError("residual logistic: no training flight scores at all")
    fp = before[None, :] > candidates[:, None]
    tp = ~fp & faulty & (after[None, :] > candidates[:, None])
    tn = ~fp & ~faulty
    i = int(np.argmax((tp | tn).sum(axis=1)))
    upper = candidates[i + 1] if i + 1 < candidates.size else candidates[i] + 1.0
    return 0.5 * (candidates[i] + upper)


class _ResidualClassifier:
    """Residuals (1)-(2), features and the logit of (3): what both threshold rules
    share, before :class:`~.base.Detector` in their bases."""

    supervised = True
    calibrated = True
    family = "supervised classifier"

    def signals(self) -> tuple[str, ...]:
        return INPUTS

    def channels(self) -> tuple[str, ...]:
        return ("logistic",)

    def channel_outputs(self) -> tuple[str, ...]:
        return ("accel_x",)

    def _steps(self, seconds: float) -> int:
        return window_steps(seconds, self.rate_hz)

    def _fit_features(self, free: list[Sampled]) -> None:
        """Fit what the features read on the training flights' parts before onset
        (``free``): the residual models (1), on their steps after the warm-up."""
        warm = self._steps(self.warmup_s)
        self.weights_, self.sigma_ = fit_residuals(np.vstack([s.x[warm:] for s in free]))

    def _features(self, s: Sampled, first_step: int = 0) -> np.ndarray:
        """The features of every step of ``s`` (which starts at step ``first_step`` of
        its flight), shape (n, features)."""
        return residual_features(residuals(s.x, self.weights_, self.sigma_), self.rate_hz)

    def _logits(self, s: Sampled, first_step: int = 0) -> np.ndarray:
        f = self._features(s, first_step)
        return ((f - self.center_) / self.scale_) @ self.coef_ + self.intercept_

    def _lookback(self) -> int:
        """Steps before ``start`` a continued run reads again: the longest window and
        the persistence."""
        return self._steps(LONGEST_WINDOW_S) + self.persist

    def design(self, segments: list[Labelled]) -> tuple[dict, np.ndarray, np.ndarray]:
        """What the regression of a fit on ``segments`` reads: the feature models
        (:attr:`feature_state`, fitted on the parts before onset), and the features
        and labels of the steps after the warm-up, positives as ``positives`` says."""
        warm = self._steps(self.warmup_s)
        free, rows, labels = [], [], []
        for seg in segments:
            t, late = seg.t, np.arange(seg.t.size) >= warm
            fault = np.zeros(t.size, bool) if seg.onset_s is None else t >= seg.onset_s
            free.append(seg.sampled if seg.onset_s is None else seg.sampled.before(seg.onset_s))
            keep = late & ~(fault & seg.emergency_trajectory & (self.positives == "no_emr"))
            rows.append((seg.sampled, keep))
            labels.append(fault[keep])
        self._fit_features(free)
        F = np.vstack([self._features(s)[keep] for s, keep in rows])
        y = np.concatenate(labels)
        if np.unique(y).size < 2:
            raise CalibrationError("residual logistic: the training steps hold "
                                   f"{'only faulty' if y.all() else 'no faulty'} steps; "
                                   "the classifier needs both")
        return {n: getattr(self, n) for n in self.feature_state if n in vars(self)}, F, y

    #: what :meth:`_fit_features` learns, in the order it sets it
    feature_state = ("weights_", "sigma_")

    def fit_model(self, segments: list[Labelled]) -> _ResidualClassifier:
        """Fit (1) on the nominal steps and the logistic regression on the steps after
        the warm-up, positives as ``positives`` says; return self. The features of a
        fit (:meth:`design`) are kept in :data:`DESIGNS`: candidates that differ in
        :math:`C` alone read the same."""
        if self.positives not in ("no_emr", "all"):
            raise ValueError(f"positives must be 'no_emr' or 'all', got {self.positives!r}")
        shaping = {k: v for k, v in self.get_params().items()
                   if k != "C" and k not in self.threshold_params}
        key = fit_key(self, segments_data(segments), shaping)
        design = DESIGNS.get(key)
        if design is None:
            design = self.design(segments)
            DESIGNS.put(key, design)
        state, F, y = design
        self.__dict__.update(state)
        self.center_ = F.mean(axis=0)
        std = F.std(axis=0)
        self.scale_ = np.where(std > 0, std, 1.0)
        # imported here: every job imports the registry, only this method needs it
        from sklearn.linear_model import LogisticRegression

        model = LogisticRegression(C=self.C, class_weight="balanced", max_iter=5000)
        model.fit((F - self.center_) / self.scale_, y)
        self.coef_, self.intercept_ = model.coef_[0].copy(), float(model.intercept_[0])
        return self

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: object | None = None) -> tuple[np.ndarray, dict]:
        """The scores (3) of steps ``start:``, in one pass; a run continued from a
        :meth:`snapshot` reads again the :meth:`_lookback` steps before ``start``."""
        self._check_fitted("coef_")
        if state is not None and state != self.snapshot():
            raise StaleStateError(f"{type(self).__name__}: the state to continue from was "
                                  "taken under another fit or other parameters")
        first = max(start - self._lookback(), 0)
        logit = self._logits(s.since(first), first)
        n = self.persist
        low = np.full(logit.size, np.nan)
        if logit.size >= n:
            low[n - 1:] = sliding_window_view(logit, n).min(axis=1)            # m of (3)
        step = np.arange(first, s.t.size)
        armed = np.isfinite(low) & (step >= self._steps(self.warmup_s))
        score = np.full(logit.size, np.nan)
        with np.errstate(under="ignore"):     # a far negative logit's e^m is 0: right
            score[armed] = np.logaddexp(0.0, low[armed])                      # (3)
        score = score[start - first:]
        return score[:, None], ({"logistic/logit": logit[start - first:]} if probes else {})

    def snapshot(self) -> str:
        """What a run continues from: the fit alone (a step reads its window again)."""
        return fit_token(self)

    def reset(self) -> _ResidualClassifier:
        self._check_fitted("coef_")
        self.window_ = deque(maxlen=self._steps(LONGEST_WINDOW_S))
        self.logits_ = deque(maxlen=self.persist)
        self.step_ = 0
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        self.window_.append(residuals(np.asarray(x, float)[None, :], self.weights_,
                                      self.sigma_)[0])
        # the batch's features of the window's last step: the same sums in the same order
        f = residual_features(np.array(self.window_), self.rate_hz)[-1]
        self.logits_.append(float(((f - self.center_) / self.scale_) @ self.coef_
                                  + self.intercept_))
        self.step_ += 1
        armed = len(self.logits_) == self.persist and self.step_ > self._steps(self.warmup_s)
        # NaN if any logit of the window is, as run()'s min (Python's min would depend on
        # where the NaN sits); armed on a finite minimum only, as run()
        low = float(np.min(self.logits_)) if armed else math.nan            # m of (3)
        with np.errstate(under="ignore"):
            return np.array([np.logaddexp(0.0, low) if math.isfinite(low) else math.nan])

    def probes(self) -> dict[str, float]:
        logits = getattr(self, "logits_", ())
        return {"logistic/logit": logits[-1] if logits else math.nan}

    def _model_report(self) -> dict:
        return {"weights": {y: w.tolist() for y, w in self.weights_.items()},
                "sigma": self.sigma_, "coef": self.coef_.tolist(),
                "intercept": self.intercept_, "center": self.center_.tolist(),
                "scale": self.scale_.tolist()}


class ResidualLogistic(_ResidualClassifier, MaximaThresholds, Detector):
    """The study's classifier (module docstring) under this project's protocol:
    supervised on the other dates' flights, thresholds from out-of-sample fault-free
    per-flight maxima.

    Parameters
    ----------
    positives : {"no_emr", "all"}
        Which faulty flights give label-1 steps.
    C : float
        Inverse regularisation strength of the logistic regression.
    persist : int
        :math:`n` of (3), steps.
    warmup_s : float
        No score, and no training step, in the first this many seconds of a run.
    margin_s : float
        A faulty flight's fault-free segment ends this long before onset (as
        calibration's ``margin_s``: the onset is known to 0.5 s).
    false_alarm : float
        Per-flight false-alarm level of the threshold.
    rate_hz : float
        Grid rate, Hz.

    Attributes
    ----------
    weights_, sigma_ : dict
        Per channel of (1), its coefficients and nominal residual spread.
    center_, scale_ : ndarray
        The features' standardisation.
    coef_, intercept_ : ndarray, float
        The logistic regression's :math:`\\boldsymbol\\beta` and :math:`b`.
    """

    def __init__(self, positives="no_emr", C=0.1, persist=5, warmup_s=WARMUP_S, margin_s=1.0,
                 false_alarm=0.1, rate_hz=10.0):
        self.positives = positives
        self.C = C
        self.persist = persist
        self.warmup_s = warmup_s
        self.margin_s = margin_s
        self.false_alarm = false_alarm
        self.rate_hz = rate_hz

    def fit(self, segments: list[Labelled]) -> ResidualLogistic:
        """Per-flight maxima, each by the model fitted without the flight's date; then
        the model on every segment, and the thresholds."""
        folds = leave_one_date_out(segments)
        if len(folds) < 2:
            raise CalibrationError("residual logistic: the out-of-sample maxima need "
                                   "training flights of two dates or more, got "
                                   f"{[d for d, _, _ in folds]}")
        splits = [(training, [s for s in (free_part(h, self.margin_s) for h in held)
                              if s.t.size]) for _, training, held in folds]
        return self.fit_out_of_sample(segments, splits)

    def fitted(self) -> dict:
        return {**super().fitted(), "model": self._model_report()}


class ResidualLogisticPublished(_ResidualClassifier, Detector):
    """The study's classifier with the study's threshold rule (module docstring): a
    reference row. Its parameters are :class:`ResidualLogistic`'s, less ``margin_s``
    and ``false_alarm``; ``positives`` is ``"all"``, as the study's.

    Attributes
    ----------
    threshold_ : float
        The threshold of best training accuracy (:func:`best_accuracy_threshold`).
    training_accuracy_ : float
        That accuracy, on the training flights scored in sample.
    flight_maxima_ : dict
        Per training flight, its largest score before onset and from onset on, and
        whether it is faulty: what the threshold was chosen on, and what
        :meth:`pool_thresholds` draws from.
    """

    def __init__(self, positives="all", C=0.1, persist=5, warmup_s=WARMUP_S,
                 rate_hz=10.0):
        self.positives = positives
        self.C = C
        self.persist = persist
        self.warmup_s = warmup_s
        self.rate_hz = rate_hz

    def fit(self, segments: list[Labelled]) -> ResidualLogisticPublished:
        """The model, then the threshold of best accuracy on its training flights."""
        self.fit_model(segments)
        self.flight_maxima_ = {}
        for seg in segments:
            score = self.run(seg.sampled)[0][:, 0]
            fault = (np.zeros(seg.t.size, bool) if seg.onset_s is None
                     else seg.t >= seg.onset_s)
            self.flight_maxima_[seg.flight] = (_largest(score[~fault]), _largest(score[fault]),
                                               seg.onset_s is not None)
        before, after, faulty = map(np.array, zip(*self.flight_maxima_.values(), strict=True))
        self.threshold_ = best_accuracy_threshold(before, after, faulty)
        fp = before > self.threshold_
        right = ~fp & np.where(faulty, after > self.threshold_, True)
        self.training_accuracy_ = float(right.mean())
        return self

    def thresholds(self) -> np.ndarray:
        self._check_fitted("threshold_")
        return np.array([self.threshold_])

    def pool_thresholds(self, pools: list[dict[str, int]]) -> np.ndarray:
        """Per pool (flight -> times drawn), the threshold of best accuracy on the
        training flights drawn, each counted as often as it is drawn, the model kept;
        NaN where the pool's flights give no finite score. Shape (pools, 1)."""
        self._check_fitted("threshold_")
        out = np.full((len(pools), 1), np.nan)
        for i, pool in enumerate(pools):
            drawn = [m for f, m in self.flight_maxima_.items() for _ in range(pool.get(f, 0))]
            if drawn:
                with contextlib.suppress(CalibrationError):
                    out[i, 0] = best_accuracy_threshold(
                        *map(np.array, zip(*drawn, strict=True)))
        return out

    def fitted(self) -> dict:
        self._check_fitted("threshold_")
        return {"threshold": self.threshold_, "training_accuracy": self.training_accuracy_,
                "flight_maxima": json_ready(self.flight_maxima_), "model": self._model_report()}


def _largest(score: np.ndarray) -> float:
    """The largest finite score, or -inf where there is none."""
    finite = score[np.isfinite(score)]
    return float(finite.max()) if finite.size else -math.inf
