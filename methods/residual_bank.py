r"""A bank of physical residuals, each scored for a step, with thresholds read from the
per-flight maxima of fault-free flights.

Each channel :math:`c` is a static linear model of one fresh sensor :math:`y_c` on
regressors :math:`z_i` (setpoints, and the attitude the autopilot holds) at lags
:math:`L_l` counted in seconds:

.. math::

    y_c(t) = \theta_c^T \varphi_c(t) + e_c(t), \qquad
    \varphi_c(t) = [1,\ z_1(t - L_1),\ \dots,\ z_m(t - L_l)]                   (1)

evaluated at the grid steps where :math:`y_c` is a new measurement (event-driven: the
IMU's ~10 Hz, not the grid's rows or the ~2.5 Hz at which ALFA's measured attitude
changes). There is no :math:`y_c(t-1)` among the regressors, so a lasting fault leaves
a lasting residual, not one innovation.

The score is the step in the residual: the mean of the fresh residuals of the last
:math:`W` seconds against their mean over the :math:`B` seconds before, in units of
:math:`\sigma_c`, the standard deviation of that step under no fault:

.. math::

    d_c(t) = \left(\bar e_c(t - W, t] - \bar e_c(t - W - B, t - W]\right) / \sigma_c  (2)

The baseline takes out each flight's own sensor bias and slow drift, which differ
between flights by as much as a fault's step. :math:`\theta_c` is fitted by least
squares on fault-free data in this same step form (:meth:`ResidualBank.fit_models`),
so the offsets drop out of the fit too. The short window is the persistence
requirement: one wild sample moves :math:`d_c` by :math:`1/n_W` of its size. A
one-sided channel scores :math:`s_c = -d_c` (thrust: only a loss is a fault), the
others :math:`s_c = |d_c|`. The score is NaN for the first :math:`W + B` seconds of
the flight, and while either window holds no fresh residual.

Thresholds count false alarms per flight, not per sample. For each channel the
maxima :math:`M_{c,j} = \max_t s_c(t)` over the fault-free training segments
:math:`j` (whole fault-free flights, and the others up to onset) are fitted with a
Gumbel law, each capped first so that one extreme flight moves it little
(:func:`~.extremes.gumbel_threshold`), and

.. math::

    \gamma_c = F^{-1}_{\mathrm{Gumbel}}(1 - \alpha / C;\ \hat\mu_c, \hat\beta_c)    (3)

so that a fault-free flight like the training ones alarms on any of the :math:`C`
channels with probability about :math:`\alpha` (Bonferroni). :math:`\alpha = 0.1`
allows one false alarm in ten fault-free flights.

The default models (:data:`DEFAULT_MODELS`), one per physical signature:

``thrust``
    body-axis specific force :math:`a_x \approx (T - D)/m + g\sin\theta`: the engine's
    thrust, against the pitch, what the autopilot's energy control asks of the throttle
    (the commanded pitch and the altitude error) and the squared roll (the drag of a
    turn). One-sided: a lost engine leaves the autopilot asking for more energy while
    :math:`a_x` falls.
``side``
    lateral specific force :math:`a_y`, zero in a coordinated turn; a stuck rudder
    sideslips. Against the yaw and roll rates and :math:`\sin\phi`.
``pitch``
    pitch rate against the pitch error and command, and :math:`\phi^2` (the pitch rate
    of a level turn): the elevator.
``roll``
    roll rate against the roll error and command: the ailerons.
``yaw``
    yaw rate against :math:`\tan\phi`, the coordinated turn :math:`r = g\tan\phi/V`,
    and the roll rate: the rudder.

Regressors are names from :data:`alfa_bench.data.SIGNALS`, in radians where the signal
is in degrees, optionally wrapped as ``sin(.)``, ``tan(.)`` or ``sq(.)`` (the square).
No regressor is a signal the fault emulation writes.

Choices, argued from fault-free data and the physics, not from scores. Regressors are
setpoints and the attitude the autopilot holds; the translational response (climb
rate, normal force) is left out because a lost engine moves it within the window and
the model would explain the fault away. Of the thrust regressor sets, the one with
the altitude error predicts the fault-free step best (leave-one-day-out :math:`R^2`
0.60 against 0.52 without it). Lags 0, 0.5, 1
and 2 s span the attitude loop's response (the measured roll follows its command about
1 s late); ``window_s = 1`` holds 10 IMU samples and keeps a step's detection within
about a second; ``baseline_s = 20`` is long against a manoeuvre's few seconds and
shorter than the 30 s before the earliest onset in ALFA; ``rate_hz = 20`` is the rate
of ALFA's attitude rows.
"""

from __future__ import annotations

import math
import re
from functools import cache

import numpy as np

from alfa_bench.data import SIGNALS, Sampled

from .base import CalibrationError, Detector
from .extremes import MaximaThresholds
from .windows import step_from_sums, step_means, window_steps

__all__ = ["DEFAULT_MODELS", "ResidualBank", "regressor_signal"]

#: One model per physical signature (module docstring): name, output, regressors and
#: whether only a drop of the output is a fault.
DEFAULT_MODELS = (
    {"name": "thrust", "output": "accel_x",
     "regressors": ["sin(pitch)", "pitch_cmd", "sq(roll_cmd)", "sq(roll)", "altitude_error"],
     "low_only": True},
    {"name": "side", "output": "accel_y", "regressors": ["yaw_rate", "roll_rate", "sin(roll)"],
     "low_only": False},
    {"name": "pitch", "output": "pitch_rate",
     "regressors": ["pitch_error", "pitch_cmd", "sq(roll)"], "low_only": False},
    {"name": "roll", "output": "roll_rate", "regressors": ["roll_error", "roll_cmd"],
     "low_only": False},
    {"name": "yaw", "output": "yaw_rate", "regressors": ["tan(roll)", "roll_rate"],
     "low_only": False},
)

_TRANSFORMS = {None: lambda v: v, "sin": np.sin, "tan": np.tan, "sq": np.square}
_REGRESSOR = re.compile(r"^(?:(sin|tan|sq)\()?([a-z_]+)\)?$")

@cache          # parsed once per name, not at every streaming step
def regressor_signal(regressor: str) -> tuple[str | None, str]:
    """``"sin(pitch)"`` -> ``("sin", "pitch")``; a bare signal name -> ``(None, name)``."""
    m = _REGRESSOR.match(regressor)
    if m is None or m.group(2) not in SIGNALS or (m.group(1) is None) != (")" not in regressor):
        raise ValueError(f"regressor {regressor!r} is not a signal name of "
                         "alfa_bench.data.SIGNALS, bare or as sin(.), tan(.) or sq(.)")
    return m.group(1), m.group(2)


class ResidualBank(MaximaThresholds, Detector):
    """Physical residuals (1), each scored for a step (2), with per-flight thresholds (3).

    Parameters
    ----------
    models : sequence of dict
        ``{"name", "output", "regressors", "low_only"}``; see :data:`DEFAULT_MODELS`.
    lags_s : sequence of float
        Lags :math:`L_l` of every regressor, s.
    window_s, baseline_s : float
        :math:`W` and :math:`B` of (2), s.
    false_alarm : float
        :math:`\\alpha`: the probability that a fault-free flight alarms on any channel.
    rate_hz : float

    Attributes
    ----------
    theta_, sigma_ : dict
        Per model: :math:`\\theta_c` of (1) and the fault-free residual's SD.
    maxima_, gamma_ : dict
        Per channel: the training segments' maxima and the threshold (3).
    history_, last_ : dict
        Streaming state: the regressors' recent values and the cumulative residual
        sums and counts of (2); the intermediates of the last step.
    """

    family = "model residuals"

    def __init__(self, models=DEFAULT_MODELS, lags_s=(0.0, 0.5, 1.0, 2.0), window_s=1.0,
                 baseline_s=20.0, false_alarm=0.1, rate_hz=20.0):
        self.models = models
        self.lags_s = lags_s
        self.window_s = window_s
        self.baseline_s = baseline_s
        self.false_alarm = false_alarm
        self.rate_hz = rate_hz

    def signals(self) -> tuple[str, ...]:
        names = [regressor_signal(r)[1] for m in self.models for r in m["regressors"]]
        return tuple(dict.fromkeys([*names, *(m["output"] for m in self.models)]))

    def channels(self) -> tuple[str, ...]:
        return tuple(m["name"] for m in self.models)

    def channel_outputs(self) -> tuple[str, ...]:
        return tuple(m["output"] for m in self.models)

    # -- the models (1) and steps (2), batch ----------------------------------------

    def _lags(self) -> list[int]:
        return [round(lag * self.rate_hz) for lag in self.lags_s]

    def _regressors(self, x: np.ndarray, names) -> np.ndarray:
        """The transformed regressors of every model, columns in model order, from the
        signal rows ``x`` (any leading shape) in the order ``names``."""
        cols = {n: i for i, n in enumerate(names)}
        out = []
        for m in self.models:
            for reg in m["regressors"]:
                fn, name = regressor_signal(reg)
                v = x[..., cols[name]]
                out.append(_TRANSFORMS[fn](np.deg2rad(v) if SIGNALS[name].unit == "deg" else v))
        return np.stack(out, axis=-1)

    def _design(self, s: Sampled) -> list[np.ndarray]:
        """Per model, :math:`\\varphi_c` of (1) at every step (NaN rows until the longest
        lag has history)."""
        z = self._regressors(s.x, s.names)
        n, lags = s.t.size, self._lags()
        out, j = [], 0
        for m in self.models:
            k = len(m["regressors"])
            phi = np.full((n, 1 + k * len(lags)), np.nan)
            phi[:, 0] = 1.0
            for li, lag in enumerate(lags):
                phi[lag:, 1 + li * k: 1 + (li + 1) * k] = z[:max(n - lag, 0), j:j + k]
            phi[:max(lags)] = np.nan
            out.append(phi)
            j += k
        return out

    def fit_models(self, segments: list[Sampled]) -> ResidualBank:
        r"""Fit :math:`\theta_c` and :math:`\sigma_c` on fault-free ``segments``; return
        self.

        The model is fitted in the form it is scored in: (2) is linear in the data, so
        the step of the residual is :math:`\Delta y_c - \theta_c^T \Delta\varphi_c`
        (:math:`\Delta` the same window difference of each column), and least squares
        on the steps gives the :math:`\theta_c` whose step is smallest under no fault.
        Each flight's own offsets (a sensor bias, the altitude error the autopilot's
        integrator has settled on) drop out. The intercept, which drops out too, is
        set to the mean residual; :math:`\sigma_c` is the standard deviation of the
        fitted step, so :math:`d_c` is in units of the fault-free step.
        """
        cols = {n: i for i, n in enumerate(self.signals())}
        nw, nb = self._windows()
        designs = [self._design(s) for s in segments]
        self.theta_, self.sigma_ = {}, {}
        for c, m in enumerate(self.models):
            dy, dphi, levels = [], [], []
            for s, design in zip(segments, designs, strict=True):
                y, phi = s.x[:, cols[m["output"]]], design[c]
                have = s.fresh[:, cols[m["output"]]] & np.isfinite(phi).all(axis=1)
                step = step_means(np.column_stack([y, phi[:, 1:]]), have, nw, nb)
                ok = np.isfinite(step).all(axis=1)
                dy.append(step[ok, 0])
                dphi.append(step[ok, 1:])
                levels.append(np.column_stack([y, phi[:, 1:]])[have])
            dy, dphi, levels = np.concatenate(dy), np.vstack(dphi), np.vstack(levels)
            if dy.size <= dphi.shape[1]:
                raise CalibrationError(f"residual bank: {dy.size} fault-free steps of "
                                 f"{m['output']} cannot fit the {dphi.shape[1]} parameters "
                                 f"of model {m['name']!r}")
            slope, *_ = np.linalg.lstsq(dphi, dy, rcond=None)     # min sum (dy - dphi' theta)^2
            intercept = float(np.mean(levels[:, 0] - levels[:, 1:] @ slope))
            self.theta_[m["name"]] = np.r_[intercept, slope]
            self.sigma_[m["name"]] = float(np.std(dy - dphi @ slope))
        return self

    def residuals(self, s: Sampled) -> tuple[np.ndarray, np.ndarray]:
        """Per step and model: the prediction and the residual of (1), NaN where the
        output is not fresh or the lags lack history; shape (n, C) each."""
        cols = {n: i for i, n in enumerate(s.names)}
        pred = np.full((s.t.size, len(self.models)), np.nan)
        res = np.full_like(pred, np.nan)
        for c, (m, phi) in enumerate(zip(self.models, self._design(s), strict=True)):
            y = s.x[:, cols[m["output"]]]
            ok = s.fresh[:, cols[m["output"]]] & np.isfinite(phi).all(axis=1)
            pred[ok, c] = phi[ok] @ self.theta_[m["name"]]       # y_hat = theta' phi
            res[ok, c] = y[ok] - pred[ok, c]                     # e = y - y_hat
        return pred, res

    def _windows(self) -> tuple[int, int]:
        return window_steps(self.window_s, self.rate_hz), window_steps(self.baseline_s,
                                                                      self.rate_hz)

    def steps(self, residuals: np.ndarray) -> np.ndarray:
        """:math:`d_c` of (2) at every step from the :meth:`residuals`, shape (n, C)."""
        sigma = np.array([self.sigma_[m["name"]] for m in self.models])
        return step_means(residuals, np.isfinite(residuals), *self._windows()) / sigma

    def scores(self, d: np.ndarray) -> np.ndarray:
        """:math:`s_c` from :math:`d_c`: one-sided where ``low_only``."""
        low = np.array([bool(m["low_only"]) for m in self.models])
        return np.where(low, -d, np.abs(d))

    # -- calibration -----------------------------------------------------------------

    def fit_model(self, segments: list[Sampled]) -> ResidualBank:
        """The models (1) and scales (2): :meth:`fit_models`; the thresholds (3) come
        from :class:`~.extremes.MaximaThresholds`."""
        return self.fit_models(segments)

    def fitted(self) -> dict:
        self._check_fitted("gamma_")
        return {m["name"]: {"theta": self.theta_[m["name"]].tolist(),
                            "sigma": self.sigma_[m["name"]],
                            "segment_maxima": self.maxima_[m["name"]],
                            "gamma": self.gamma_[m["name"]]} for m in self.models}

    # -- streaming -------------------------------------------------------------------

    def reset(self) -> ResidualBank:
        self._check_fitted("sigma_")
        span = window_steps(self.window_s, self.rate_hz) + window_steps(self.baseline_s,
                                                                       self.rate_hz)
        c = len(self.models)
        names = self.signals()
        self.history_ = {
            "z": [],                                   # transformed regressors, newest last
            "total": np.zeros((span + 1, c)),          # cumulative residual sums, ring
            "count": np.zeros((span + 1, c), dtype=np.int64),
            "k": -1,
            # fixed for the run: where each output sits, the lags, the scales
            "names": names, "outputs": [names.index(m["output"]) for m in self.models],
            "lags": self._lags(), "nw": window_steps(self.window_s, self.rate_hz),
            "sigma": np.array([self.sigma_[m["name"]] for m in self.models]),
        }
        self.last_ = {"prediction": np.full(c, np.nan), "residual": np.full(c, np.nan),
                      "step": np.full(c, np.nan)}
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        h = self.history_
        lags = h["lags"]
        h["k"] += 1
        h["z"].append(self._regressors(x, h["names"]))
        del h["z"][:-(max(lags) + 1)]
        pred = np.full(len(self.models), np.nan)
        res = np.full(len(self.models), np.nan)
        if h["k"] >= max(lags):
            j = 0
            for c, m in enumerate(self.models):
                k = len(m["regressors"])
                if fresh[h["outputs"][c]]:
                    phi = np.concatenate([[1.0], *(h["z"][-1 - lag][j:j + k] for lag in lags)])
                    pred[c] = phi @ self.theta_[m["name"]]          # y_hat = theta' phi
                    res[c] = x[h["outputs"][c]] - pred[c]            # e = y - y_hat
                j += k
        span = h["total"].shape[0] - 1
        ring = h["k"] % (span + 1)
        prev = (h["k"] - 1) % (span + 1)
        have = np.isfinite(res)
        if h["k"] == 0:
            h["total"][ring], h["count"][ring] = np.where(have, res, 0.0), have
        else:
            h["total"][ring] = h["total"][prev] + np.where(have, res, 0.0)
            h["count"][ring] = h["count"][prev] + have
        d = np.full(len(self.models), np.nan)
        if h["k"] >= span:
            at = [(h["k"] - back) % (span + 1) for back in (0, h["nw"], span)]
            d = step_from_sums(*(h["total"][i] for i in at),
                               *(h["count"][i] for i in at)) / h["sigma"]
        self.last_ = {"prediction": pred, "residual": res, "step": d}
        return self.scores(d)

    def probes(self) -> dict[str, float]:
        last = getattr(self, "last_", None)
        return {f"{m['name']}/{key}": (float(last[key][c]) if last else math.nan)
                for c, m in enumerate(self.models) for key in ("prediction", "residual", "step")}

    def memory_steps(self) -> int:
        """The steps before a step that its score depends on: the longest lag of (1)
        and both windows of (2)."""
        return max(self._lags()) + sum(self._windows())

    def snapshot(self) -> dict:
        """Nothing: a score depends on the last :meth:`memory_steps` steps only, which
        a continued :meth:`run` reads again from its segment."""
        return {}

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: dict | None = None) -> tuple[np.ndarray, dict]:
        """The batch form of :meth:`update` over ``s`` (equal to rounding); continued
        from step ``start`` (any ``state``), it runs from :meth:`memory_steps` before."""
        self.reset()
        start = 0 if state is None else start
        first = max(0, start - self.memory_steps())
        pred, res = self.residuals(s.since(first))
        d = self.steps(res)[start - first:]
        pred, res = pred[start - first:], res[start - first:]
        score = self.scores(d)
        kept = {}
        if probes:
            for c, m in enumerate(self.models):
                kept.update({f"{m['name']}/prediction": pred[:, c],
                             f"{m['name']}/residual": res[:, c], f"{m['name']}/step": d[:, c]})
        return score, kept
