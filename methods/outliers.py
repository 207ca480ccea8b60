r"""Generic outlier detectors (PyOD, river) as runs: what a researcher tries first.

A model of `PyOD <https://pyod.readthedocs.io>`_ (``IForest``, ``ECOD``, ``COPOD``,
``HBOS``, ``PCA``, ``KNN``, ``LOF``, ...) or of river's ``anomaly`` module
(``HalfSpaceTrees``, ``LODA``, ...) scores each grid step from the features of a
causal window of honest signals. Over the last :math:`W` steps
(``window_s``) of each signal :math:`x` it sees

.. math::

    f(t) = \big(x(t),\ \bar x_W(t),\ s_W(t),\ x(t) - x(t - W + 1)\big)

(the value, the window's mean, its standard deviation and its change), scaled by the
fault-free training data: standardised for a PyOD model, as PyOD's ``standardizer``
does, and min-max scaled for a river model, as river's ``MinMaxScaler`` does before a
half-space tree. The model is the library's, with its defaults (a seed is set where
it takes one and none was given, so that a run repeats); it is fitted on the
fault-free segments of the other dates, a river model learning them row by row and
then frozen (a half-space tree's window, unless set, is every row learned, so that its
reference is all of them, not the last 250). Its outlier score (PyOD's
``decision_function``, river's ``score_one``) is the channel's score.

Thresholds come from per-flight maxima (:class:`~.extremes.MaximaThresholds`), taken
out of sample: each calibration flight is scored by the model fitted on the flights
of the other dates (a model scores its own training rows low: a nearest-neighbour
distance is then zero; and flights of one date share its weather and trim), and the
model that scores is fitted on all of them. A flight is scored in one batch call of the model
(:meth:`OutlierModel.run`): a PyOD model costs milliseconds a call and microseconds a
row.

With ``features="residuals"`` the same model reads, instead of windows, a public
study's 25 features of five physical residuals
(:func:`~.residual_logistic.residual_features`), its residual models fitted on the
fault-free training rows: what the features give, apart from the study's supervised
learner (``results/tables/features_learners.md``).
"""

from __future__ import annotations

import copy
import functools
import importlib
import importlib.metadata
import inspect
import math
import re
from collections import deque
from pathlib import Path

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from alfa_bench.data import Sampled

from .base import (
    CalibrationError,
    Detector,
    StaleStateError,
    fit_token,
    json_ready,
    leave_one_date_out,
)
from .extremes import MaximaThresholds
from .fits import kept_fit
from .residual_logistic import INPUTS as RESIDUAL_INPUTS
from .residual_logistic import (
    LONGEST_WINDOW_S,
    WARMUP_S,
    fit_residuals,
    residual_features,
    residuals,
)
from .windows import window_steps

__all__ = ["DEFAULT_SIGNALS", "FEATURES", "FEATURE_KINDS", "TRANSDUCTIVE",
           "OutlierModel", "PyODDetector", "RiverDetector", "alone_ecdf_scores",
           "window_features"]

#: the honest signals a generic model reads by default: attitude against its command,
#: body rates and specific force from the IMU, climb rate and the altitude error
DEFAULT_SIGNALS = ("roll_error", "pitch_error", "roll_rate", "pitch_rate", "yaw_rate",
                   "accel_x", "accel_y", "vel_up", "altitude_error")

#: the features of each signal over its window, in order
FEATURES = ("value", "mean", "std", "change")

#: what a model can read: window features of the signals, or the study's residual ones
FEATURE_KINDS = ("windows", "residuals")


def window_features(window: np.ndarray) -> np.ndarray:
    """The features :data:`FEATURES` of windows of shape (..., m, W), oldest first:
    shape (..., 4 m), signal by signal."""
    f = np.stack([window[..., -1], window.mean(axis=-1), window.std(axis=-1),
                  window[..., -1] - window[..., 0]], axis=-1)
    return f.reshape(*f.shape[:-2], -1)


class OutlierModel(MaximaThresholds, Detector):
    """A library's outlier model on causal window features (module docstring); the
    library's adapter (:class:`PyODDetector`, :class:`RiverDetector`) says how it is
    built, fitted and asked for scores.

    Parameters
    ----------
    model : str or estimator, optional
        The model's class name in the library (``"IForest"``, ``"HalfSpaceTrees"``), or
        an unfitted instance (it is copied, never fitted itself); none: the library's
        :attr:`default_model`.
    params : dict, optional
        The class's parameters by name; none: the library's defaults.
    inputs : tuple of str
        Honest signals to read (:data:`DEFAULT_SIGNALS`); ``signals()`` returns them.
    window_s : float
        :math:`W`, s.
    false_alarm : float
        Per-flight false-alarm level of the threshold.
    rate_hz : float
        Grid rate, Hz.
    max_rows : int
        At most this many training rows fit the model (evenly spaced): the cost of a
        neighbour model grows with them.
    features : {"windows", "residuals"}
        What the model reads: the window features above, or a public study's 25
        features of five physical residuals (:func:`~.residual_logistic.residual_features`:
        the residual models (1) fitted by least squares on the fault-free training
        rows, no label read; ``inputs`` and ``window_s`` unused), with the study's
        warm-up: no score, and no training row, in the first
        :data:`~.residual_logistic.WARMUP_S` of a run.

    Attributes
    ----------
    estimator_ : object
        The fitted model (for ECOD and COPOD the model as built, for its parameters:
        :class:`PyODDetector`).
    center_, scale_ : ndarray
        The features' scaling, from the training rows.
    rows_ : int
        Training rows the model was fitted on.
    weights_, sigma_ : dict
        With residual features: per residual channel, its coefficients and nominal
        spread.
    """

    #: the library's name, for the records
    library: str = ""
    #: the model a run without ``model`` uses
    default_model: str = ""
    family = "generic outlier"

    def __init__(self, model=None, params=None, inputs=DEFAULT_SIGNALS, window_s=2.0,
                 false_alarm=0.1, rate_hz=2.5, max_rows=5000, features="windows"):
        self.model = model
        self.params = params
        self.inputs = inputs
        self.window_s = window_s
        self.false_alarm = false_alarm
        self.rate_hz = rate_hz
        self.max_rows = max_rows
        self.features = features

    # -- what the library adapters say ---------------------------------------------------

    def _build(self) -> object:
        """A new, unfitted estimator: a copy of ``model``, or the library's class of that
        name with ``params``; a seed set where it takes one and none was given."""
        if not isinstance(self.model, str | None):
            return copy.deepcopy(self.model)
        cls = self._resolve(self._name())
        # a copy of every value: a model may fit an estimator it was given in place
        # (PyOD's LSCP its detector_list), which must not change the run's parameters
        params = copy.deepcopy(dict(self.params or {}))
        seed = self._seed_name(cls)
        if seed is not None and params.get(seed) is None:
            params[seed] = 0
        return cls(**params)

    def check_params(self) -> None:
        """The features are known (residual ones set no window or inputs, which they
        would not read), and the model builds: its class resolves in the library and
        takes ``params``."""
        if self.features not in FEATURE_KINDS:
            raise ValueError(f"features must be one of {list(FEATURE_KINDS)}, got "
                             f"{self.features!r}")
        defaults = inspect.signature(OutlierModel).parameters
        unread = [n for n, same in (("inputs", tuple(self.inputs) == defaults["inputs"].default),
                                    ("window_s", self.window_s == defaults["window_s"].default))
                  if self._residual() and not same]
        if unread:
            raise ValueError(f"features 'residuals' read the study's signals over its own "
                             f"windows: {' and '.join(unread)} would not be read. What to "
                             "do: leave them out, or read window features")
        try:
            self._build()
        except ImportError as e:
            needs = (f"it needs {e.name}, which alfa-bench does not install ({e}). What to "
                     f"do: pip install {e.name}" if e.name else
                     f"it cannot import what it needs ({e}). What to do: install that")
            raise ValueError(f"{self.library} model {self._name()!r} cannot be built: "
                             f"{needs} (PyOD's deep models need torch), or name another "
                             "model") from None
        except (AttributeError, TypeError, ValueError) as e:
            raise ValueError(
                f"{self.library} model {self._name()!r} with params {self.params or {}} "
                f"cannot be built: {type(e).__name__}: {e}. What to do: name a model class "
                f"{self.library} has (its documentation lists them) and parameters it "
                "takes") from None
        except NameError as e:      # a module that half-imported without torch
            raise ValueError(
                f"{self.library} model {self._name()!r} cannot be built: "
                f"{type(e).__name__}: {e} (PyOD's deep models need torch, which "
                "alfa-bench does not install). What to do: pip install torch, or name "
                "another model") from None

    @staticmethod
    def _seed_name(cls) -> str | None:
        names = inspect.signature(cls).parameters
        return next((n for n in ("random_state", "seed") if n in names), None)

    def _resolve(self, name: str):
        raise NotImplementedError

    def _fit_estimator(self, estimator, X: np.ndarray):
        raise NotImplementedError

    def _score(self, estimator, X: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def _scaling(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    # -- the contract --------------------------------------------------------------------

    def signals(self) -> tuple[str, ...]:
        return RESIDUAL_INPUTS if self._residual() else tuple(self.inputs)

    def _residual(self) -> bool:
        return self.features == "residuals"

    def _name(self) -> str:
        """The model's class name."""
        if self.model is None:
            return self.default_model
        return self.model if isinstance(self.model, str) else type(self.model).__name__

    def channels(self) -> tuple[str, ...]:
        return (f"{self.library}_{self._name()}".lower(),)

    def _width(self) -> int:
        """Steps a step's features read: its window, or the residuals' longest."""
        return window_steps(LONGEST_WINDOW_S if self._residual() else self.window_s,
                            self.rate_hz)

    def _warmup(self) -> int:
        return window_steps(WARMUP_S, self.rate_hz) if self._residual() else 0

    def _features(self, s: Sampled, first: int = 0) -> np.ndarray:
        """Per grid step of ``s`` (step ``first`` of its run), its features: NaN until
        the window is full, or, with residual features, in the warm-up."""
        if self._residual():
            out = residual_features(residuals(s.x, self.weights_, self.sigma_), self.rate_hz)
            out[:max(self._warmup() - first, 0)] = np.nan
            return out
        w = self._width()
        out = np.full((s.t.size, len(self.inputs) * len(FEATURES)), np.nan)
        if s.t.size >= w:
            out[w - 1:] = window_features(sliding_window_view(s.x, w, axis=0))
        return out

    def fit_model(self, segments: list[Sampled]) -> OutlierModel:
        """Scale the training rows' features and fit the model on them (at most
        ``max_rows``, evenly spaced), or take the same fit from
        :data:`~.fits.MODEL_FITS` (:func:`~.fits.kept_fit`; the fits are deterministic:
        a seed is set)."""
        kept_fit(self, segments, self._fit_rows, self.model_state)
        return self

    #: what :meth:`fit_model` learns
    model_state = ("estimator_", "center_", "scale_", "rows_", "weights_", "sigma_")

    def _fit_rows(self, segments: list[Sampled]) -> None:
        if self._residual():
            nominal = np.vstack([seg.x[self._warmup():] for seg in segments])
            self.weights_, self.sigma_ = fit_residuals(
                nominal[~np.isnan(nominal).any(axis=1)])
        X = np.vstack([f[~np.isnan(f).any(axis=1)] for f in map(self._features, segments)])
        if len(X) < 2:
            read = ("residual features after the warm-up" if self._residual() else
                    f"full {self.window_s} s windows")
            raise CalibrationError(f"{self.channels()[0]}: {len(X)} training rows of {read}")
        if len(X) > self.max_rows:
            X = X[np.linspace(0, len(X) - 1, self.max_rows).round().astype(int)]
        self.center_, self.scale_ = self._scaling(X)
        self.estimator_ = self._fit_estimator(self._build(), (X - self.center_) / self.scale_)
        self.rows_ = len(X)

    def fit(self, segments: list[Sampled]) -> OutlierModel:
        """Per-flight maxima out of sample (module docstring), each by the model fitted
        without the flight's date; then the model fitted on every segment, and the
        thresholds."""
        folds = leave_one_date_out(segments)
        if len(folds) < 2:
            raise CalibrationError(f"{self.channels()[0]}: calibration segments of "
                                   f"{len(folds)} date(s); the out-of-sample maxima need "
                                   "two dates or more")
        return self.fit_out_of_sample(segments, [(training, held)
                                                 for _, training, held in folds])

    def fitted(self) -> dict:
        """The maxima and thresholds, and the model: its library, name, parameters,
        training rows and feature scaling."""
        out = super().fitted()
        out["model"] = {"library": self.library, "name": self.channels()[0],
                        "params": {k: v if v is None or isinstance(v, int | float | str)
                                   else repr(v) for k, v in _params(self.estimator_).items()},
                        "rows": self.rows_, "center": self.center_.tolist(),
                        "scale": self.scale_.tolist()}
        if self._residual():
            out["model"]["residuals"] = {"weights": json_ready(self.weights_),
                                         "sigma": self.sigma_}
        return out

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: object | None = None) -> tuple[np.ndarray, dict]:
        """The scores of steps ``start:`` in one call of the model. A step's score reads
        the window before it and the frozen model only, so a run continued from a
        :meth:`snapshot` after ``start`` steps scores just the steps after them."""
        return self.run_many([(s, start, state)], probes)[0]

    def run_many(self, items: list[tuple[Sampled, int, object]], probes: bool = False
                 ) -> list[tuple[np.ndarray, dict]]:
        """:meth:`run` of each ``(s, start, state)``, every row of them in one call of
        the model."""
        self._check_fitted("estimator_")
        if any(state is not None and state != self.snapshot() for _, _, state in items):
            raise StaleStateError(f"{type(self).__name__}: the state to continue from was "
                                  "taken under another fit or other parameters")
        features = []
        for s, start, _ in items:
            first = max(start - self._width() + 1, 0)
            features.append(self._features(s.since(first), first)[start - first:])
        f = np.vstack(features)
        score = np.full(f.shape[0], np.nan)
        ok = ~np.isnan(f).any(axis=1)
        if ok.any():
            score[ok] = self._score(self.estimator_, (f[ok] - self.center_) / self.scale_)
        name = f"{self.channels()[0]}/score"
        return [(part[:, None], {name: part} if probes else {})
                for part in np.split(score, np.cumsum([len(x) for x in features])[:-1])]

    def snapshot(self) -> str:
        """What a run continues from: the fit alone (the model is frozen, and a step's
        features are read again from the window before it)."""
        return fit_token(self)

    def reset(self) -> OutlierModel:
        self._check_fitted("estimator_")
        self.window_ = deque(maxlen=self._width())
        self.step_ = 0
        self.last_ = math.nan
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        self.last_, f = math.nan, None
        if self._residual():
            self.window_.append(residuals(x[None, :], self.weights_, self.sigma_)[0])
            if self.step_ >= self._warmup():
                # the batch's features of the window's last step, bit for bit
                f = residual_features(np.array(self.window_), self.rate_hz)[-1]
        else:
            self.window_.append(x)
            if len(self.window_) == self.window_.maxlen:
                f = window_features(np.array(self.window_).T)
        self.step_ += 1
        if f is not None and not np.isnan(f).any():   # as run_many: a NaN feature, no score
            self.last_ = float(self._score(self.estimator_,
                                           ((f - self.center_) / self.scale_)[None, :])[0])
        return np.array([self.last_])

    def probes(self) -> dict[str, float]:
        return {f"{self.channels()[0]}/score": getattr(self, "last_", math.nan)}


def _params(estimator) -> dict:
    """The parameters ``estimator`` was built with: scikit-learn's and PyOD's
    ``get_params``, river's ``_get_params``."""
    get = getattr(estimator, "get_params", None)
    if get is None:
        return estimator._get_params() if hasattr(estimator, "_get_params") else {}
    try:
        return get(deep=False)
    except TypeError:
        return get()


class PyODDetector(OutlierModel):
    r"""A PyOD model (``pyod.models``), fitted on the standardised features in one call
    and scored by ``decision_function`` in one call per flight.

    ECOD and COPOD score a batch *transductively*: ``decision_function(X)`` takes its
    empirical CDFs and skewness over the training rows and every row of ``X`` together,
    so a row's score would move with the rows after it (the contract's causality check
    finds it). Here each row is scored as ``decision_function`` scores it alone, all
    rows in one vectorised pass (:func:`alone_ecdf_scores`; a test checks it against
    PyOD row by row), from the sorted training rows and their sums alone: the model's
    own ``fit`` (its training rows and their tail probabilities, 7 MB for 5000 rows)
    is never used, so it is not called, and ``estimator_`` is the model as built, for
    its parameters."""

    library = "pyod"
    default_model = "IForest"
    model_state = (*OutlierModel.model_state, "train_sorted_", "train_sums_")

    def _resolve(self, name: str):
        module = importlib.import_module(f"pyod.models.{pyod_module(name)}")
        return getattr(module, name)

    def _scaling(self, X):
        std = X.std(axis=0)
        return X.mean(axis=0), np.where(std > 0, std, 1.0)

    def _fit_estimator(self, estimator, X):
        if type(estimator).__name__ in TRANSDUCTIVE:
            self.train_sorted_ = np.sort(X, axis=0)
            self.train_sums_ = np.stack([X.sum(axis=0), (X ** 2).sum(axis=0),
                                         (X ** 3).sum(axis=0)])
            return estimator
        return estimator.fit(X)

    def warm(self) -> None:
        """Fit and score a model of this class once per process on a small fixed
        matrix, then drop it: PyOD's HBOS compiles its scoring with numba at its first
        fit (5 s), which the jobs forked after it then find done. NumPy's global random
        state is put back. A model the matrix cannot fit is left cold: its job's own fit
        says what is wrong with it."""
        kind = self._name()
        if kind in TRANSDUCTIVE or kind in _WARM:
            return
        _WARM.add(kind)
        estimator = self._build()
        rows = np.arange(256.0)
        X = np.column_stack([np.sin(rows), np.cos(0.7 * rows), np.sin(0.3 * rows) ** 2,
                             np.cos(1.3 * rows) ** 3])
        # a model built without a seed would draw from the global state, as jobs do
        state = np.random.get_state()  # noqa: NPY002
        try:
            estimator.fit(X)
            estimator.decision_function(X)
        except Exception:  # the job's own fit reports it, in the job's log
            pass
        finally:
            np.random.set_state(state)  # noqa: NPY002

    def _score(self, estimator, X):
        kind = type(estimator).__name__
        if kind in TRANSDUCTIVE:
            return alone_ecdf_scores(self.train_sorted_, self.train_sums_, X, kind)
        return np.asarray(estimator.decision_function(X), dtype=float)


#: PyOD models whose decision_function scores a batch transductively
TRANSDUCTIVE = ("ECOD", "COPOD")
#: the PyOD model classes this process has warmed (PyODDetector.warm)
_WARM: set[str] = set()


def alone_ecdf_scores(train_sorted: np.ndarray, sums: np.ndarray, X: np.ndarray,
                      kind: str) -> np.ndarray:
    r"""ECOD's or COPOD's ``decision_function`` of each row of ``X`` on its own: over
    the :math:`n` training rows (``train_sorted``, each column sorted) and the row
    :math:`x`, the tail probabilities of feature :math:`j`

    .. math::

        U_l = -\ln \frac{\#\{x_{ij} \le x_j\} + 1}{n + 1}, \qquad
        U_r = -\ln \frac{\#\{x_{ij} \ge x_j\} + 1}{n + 1},

    the sign of the skewness of the :math:`n + 1` values (from the training sums
    ``sums`` of :math:`x, x^2, x^3`) choosing the tail, :math:`U_s`; the score is
    :math:`\sum_j \max(U_l, U_r, U_s)` (ECOD) or
    :math:`\sum_j \max(U_s, (U_l + U_r)/2)` (COPOD)."""
    n = train_sorted.shape[0]
    le = np.stack([np.searchsorted(train_sorted[:, j], X[:, j], side="right")
                   for j in range(X.shape[1])], axis=1)
    ge = n - np.stack([np.searchsorted(train_sorted[:, j], X[:, j], side="left")
                       for j in range(X.shape[1])], axis=1)
    u_l = -np.log((le + 1) / (n + 1))
    u_r = -np.log((ge + 1) / (n + 1))
    m = n + 1
    mean = (sums[0] + X) / m
    m2 = (sums[1] + X ** 2) / m - mean ** 2
    m3 = (sums[2] + X ** 3) / m - 3 * mean * (sums[1] + X ** 2) / m + 2 * mean ** 3
    sign = np.where(m2 > 0, np.sign(m3), 0.0)
    u_s = u_l * -np.sign(sign - 1) + u_r * np.sign(sign + 1)
    if kind == "ECOD":
        return np.maximum(u_s, np.maximum(u_l, u_r)).sum(axis=1)
    return np.maximum(u_s, (u_l + u_r) / 2).sum(axis=1)


@functools.cache
def pyod_module(name: str) -> str:
    """The module of ``pyod.models`` that defines the model class ``name``, found by its
    source (``class <name>(``), so that nothing is imported but the model's own module;
    :class:`AttributeError` where no module of the installed PyOD defines it."""
    import pyod.models

    folder = Path(pyod.models.__path__[0])
    pattern = re.compile(rf"^class {re.escape(name)}\(", re.M)
    found = sorted(f.stem for f in folder.glob("*.py") if pattern.search(f.read_text()))
    if not found:
        raise AttributeError(f"no module of pyod.models {importlib.metadata.version('pyod')} "
                             f"defines a class {name}")
    return found[0]


class RiverDetector(OutlierModel):
    """A river anomaly model (``river.anomaly``): it learns the min-max scaled training
    rows one by one (``learn_one``), then is frozen and scores each step
    (``score_one``)."""

    library = "river"
    default_model = "HalfSpaceTrees"

    def _resolve(self, name: str):
        from river import anomaly

        return getattr(anomaly, name)

    def _scaling(self, X):
        low, high = X.min(axis=0), X.max(axis=0)
        return low, np.where(high > low, high - low, 1.0)

    def _fit_estimator(self, estimator, X):
        if ("window_size" in estimator._get_params()
                and "window_size" not in (self.params or {})):
            # HalfSpaceTrees scores against its last complete window of rows learned: one
            # window of every row, or it would know only the last 250 (river's default),
            # or none at all from fewer rows
            estimator = estimator.clone({"window_size": len(X)})
        for row in X:
            estimator.learn_one(dict(enumerate(row.tolist())))
        return estimator

    def _score(self, estimator, X):
        return np.array([estimator.score_one(dict(enumerate(row.tolist()))) for row in X])
