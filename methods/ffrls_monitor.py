r"""Forgetting-factor RLS parameter monitoring (Hansen, Blanke, Adrian 2014, eqs. 11-16).

Simple models relate the commanded surface deflections to the body rates (eqs. 11-13):

.. math::

    p(k) &= a_{pa}\,\delta_a(k) + b_{pa}                          && (11)\\
    q(k) &= a_{qe}\,\delta_e(k) + b_{qe}                          && (12)\\
    r(k) &= a_{ra}\,\delta_a(k) + b_{ra}\,r(k-1) + c_{ra}          && (13)

Each is estimated online by RLS with forgetting factor :math:`\lambda_f` (eqs. 14-16;
:class:`~.rls.RecursiveLeastSquares` computes the same recursion through the matrix
inversion lemma). In ALFA the rates are the raw IMU's (``mavros-imu-data_raw``, ~10 Hz,
every row a new measurement); the grid is the gyro's 10 Hz.

The paper's deflections :math:`\delta` are the servo outputs of ``rc-out``. In ALFA
those carry the fault emulation (the failed surface's channel goes flat at onset), so
the primary run replaces them with what the autopilot turns into deflections: the
attitude error (measured minus commanded, ``nav_info``) for roll and pitch, and the
measured roll for yaw, the coordinated-turn relation :math:`r \approx g \tan\phi / V`
linearised. This keeps the paper's structure (a rate against one driving signal, with
:math:`r(k-1)` for yaw) on honest inputs. The servo form (:data:`SERVO_MODELS`) stays
as the ``ffrls_monitor_servo`` run, ranked apart. Inputs are put on a common scale by
unit: PWM as :math:`(\mathrm{PWM} - 1500)/500`, the servo's fixed range mapped onto
[-1, 1]; degrees as radians.

Two tests per model, both with thresholds read from fault-free data:

``{model}_residual``
    The windowed GLRT (:mod:`.glrt`) on the prediction error :math:`\varepsilon(k)`
    of (14), centred and scaled by its fault-free mean and variance; threshold
    :math:`\gamma_r`, the :math:`1-P_F` quantile of :math:`g` on the training data.
``{model}_joint``
    The combined test of parameter change and residual statistic. The parameter
    change over the GLRT window, :math:`\Delta\hat\theta(k) = \hat\theta(k) -
    \hat\theta(k-M)`, is scored by :math:`T(k) = \Delta\hat\theta^T \Sigma^{-1}
    \Delta\hat\theta`, :math:`\Sigma` its fault-free covariance. The test fires when
    both :math:`g > \gamma_r'` and :math:`T > \gamma_\theta'`, the two lowered
    thresholds being the :math:`1-q` quantiles of :math:`g` and :math:`T` with the
    largest :math:`q` whose *joint* exceedance on the training data is at most
    :math:`P_F`. Its score is :math:`\min(g/\gamma_r', T/\gamma_\theta')`, so it fires
    above 1.

As the paper prescribes, adaptation stops while the residual statistic is above
:math:`\gamma_r'`, so a fault is not absorbed into the parameters; the bound on
:math:`\operatorname{tr}P` (``max_trace_ratio`` times that of the a-priori :math:`P`)
stops the covariance winding up in steady flight.

Fitted from fault-free data, as the paper suggests: :math:`\hat\theta(0)` and
:math:`P(0)` are the means of the final estimates over the training segments, each run
from :math:`\hat\theta = 0`, :math:`P = p_0 I`. The thresholds come from a second pass
started at those values; that pass does not freeze adaptation (the freezing rule
needs the thresholds it is computing), so the statistics it sees are those of an
estimator that never stops; under no fault the two differ only at the fraction
:math:`q` of steps above :math:`\gamma_r'`.

Choices the paper leaves open (none fitted to scores): :math:`\lambda_f = 0.98`, a
memory of :math:`1/(1-\lambda_f) = 50` samples (5 s), long enough to average the
noise, short enough to follow a failed surface within seconds; ``window_s = 2``;
``max_trace_ratio = 10``.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from alfa_bench.data import SIGNALS, Sampled

from . import kernels
from .base import Detector
from .glrt import WindowedGlrt, empirical_threshold, glrt_statistic
from .kernels import FfrlsConfig, FfrlsCount, FfrlsOut
from .rls import RecursiveLeastSquares

__all__ = ["DEFAULT_MODELS", "SERVO_MODELS", "FfRlsMonitor", "joint_thresholds",
           "normalise_inputs"]

#: eqs. (11)-(13) on honest inputs: output rate, driving signals, whether r(k-1) is a
#: regressor
DEFAULT_MODELS = (
    {"name": "roll", "output": "roll_rate", "inputs": ["roll_error"], "autoregressive": False},
    {"name": "pitch", "output": "pitch_rate", "inputs": ["pitch_error"],
     "autoregressive": False},
    {"name": "yaw", "output": "yaw_rate", "inputs": ["roll"], "autoregressive": True},
)

#: eqs. (11)-(13) as the paper states them, on the servo outputs (which carry ALFA's
#: fault emulation)
SERVO_MODELS = (
    {"name": "roll", "output": "roll_rate", "inputs": ["servo_aileron_left"],
     "autoregressive": False},
    {"name": "pitch", "output": "pitch_rate", "inputs": ["servo_elevator"],
     "autoregressive": False},
    {"name": "yaw", "output": "yaw_rate", "inputs": ["servo_aileron_left"],
     "autoregressive": True},
)

_PWM_CENTRE_US, _PWM_HALF_RANGE_US = 1500.0, 500.0


def normalise_inputs(x: np.ndarray, names) -> np.ndarray:
    """Columns ``x`` of signals ``names`` on a common scale: PWM (us) mapped from the
    servo range onto [-1, 1], degrees to radians, other units as they are."""
    units = np.array([SIGNALS[n].unit for n in names])
    out = np.array(x, dtype=float, copy=True)
    pwm, deg = units == "us", units == "deg"
    out[..., pwm] = (out[..., pwm] - _PWM_CENTRE_US) / _PWM_HALF_RANGE_US
    out[..., deg] = np.deg2rad(out[..., deg])
    return out


def joint_thresholds(g: np.ndarray, t: np.ndarray, false_alarm: float) -> tuple[float, float]:
    """Lowered thresholds :math:`(\\gamma_r', \\gamma_\\theta')` at equal marginal levels
    :math:`q`, the largest with joint exceedance of ``(g, t)`` at most ``false_alarm``."""
    ok = np.isfinite(g) & np.isfinite(t)
    g, t = g[ok], t[ok]

    def at(q):
        return (float(np.quantile(g, 1 - q, method="higher")),
                float(np.quantile(t, 1 - q, method="higher")))

    def rate(q):
        tg, tt = at(q)
        return float(np.mean((g > tg) & (t > tt)))

    lo, hi = false_alarm, 0.5
    if rate(lo) > false_alarm:
        return at(lo)
    for _ in range(40):                     # bisection on q: rate(q) grows with q
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if rate(mid) <= false_alarm else (lo, mid)
    return at(lo)


class _Model:
    def __init__(self, det: FfRlsMonitor, spec: dict, cols: dict):
        self.y_col = cols[spec["output"]]
        self.u_cols = [cols[s] for s in spec["inputs"]]
        self.u_names = list(spec["inputs"])
        self.ar = bool(spec["autoregressive"])
        self.n = len(self.u_cols) + self.ar + 1
        self.rls = RecursiveLeastSquares(self.n, det.p0, det.forgetting,
                                         det.max_trace_ratio * np.trace(det.P0_[spec["name"]])
                                         if hasattr(det, "P0_") else np.inf)
        self.y_prev = math.nan
        self.thetas = deque(maxlen=det._window() + 1)
        self.frozen = False
        self.prediction = self.residual = self.change = math.nan  # of the last step


class FfRlsMonitor(Detector):
    """FF-RLS on eqs. (11)-(13) with residual and joint parameter tests.

    Parameters
    ----------
    models : sequence of dict
        ``{"name", "output", "inputs", "autoregressive"}``; signal names from
        :data:`alfa_bench.data.SIGNALS`.
    rate_hz : float
    forgetting : float
        :math:`\\lambda_f`.
    p0 : float
        :math:`P = p_0 I` of the first calibration pass.
    false_alarm : float
        :math:`P_F` per sample, for both tests.
    window_s : float
        GLRT window and parameter-change lag :math:`M`.
    max_trace_ratio : float
        Bound on :math:`\\operatorname{tr}P` relative to the fitted a-priori :math:`P`.

    Attributes
    ----------
    theta0_, P0_ : dict
        Fitted a-priori parameters and covariance per model.
    res_mean_, res_var_, dtheta_cov_, dtheta_info_ : dict
        Fault-free statistics of :math:`\\varepsilon` and :math:`\\Delta\\hat\\theta`
        (``dtheta_info_`` the pseudo-inverse of ``dtheta_cov_``).
    gamma_r_, gamma_r_joint_, gamma_theta_joint_ : dict
        Thresholds per model.
    models_ : list
        Per-model state: ``rls`` (``theta_``, ``P_``, ``error_``, ``K_``),
        ``frozen``.
    kernel_ : dict
        Per model, the compiled kernel's counters and state after the last batch
        :meth:`run` (what :meth:`snapshot` copies).
    """

    family = "parameter monitoring"

    calibrated = True

    def __init__(self, models=DEFAULT_MODELS, rate_hz=10.0, forgetting=0.98, p0=1e3,
                 false_alarm=5e-4, window_s=2.0, max_trace_ratio=10.0):
        self.models = models
        self.rate_hz = rate_hz
        self.forgetting = forgetting
        self.p0 = p0
        self.false_alarm = false_alarm
        self.window_s = window_s
        self.max_trace_ratio = max_trace_ratio

    def signals(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(s for m in self.models for s in (*m["inputs"], m["output"])))

    def channels(self) -> tuple[str, ...]:
        return tuple(f"{m['name']}_{test}" for m in self.models for test in ("residual", "joint"))

    def channel_outputs(self) -> tuple[str, ...]:
        return tuple(m["output"] for m in self.models for _ in ("residual", "joint"))

    def thresholds(self) -> np.ndarray:
        self._check_fitted("gamma_r_")
        return np.array([g for m in self.models for g in (self.gamma_r_[m["name"]], 1.0)])

    def probes(self) -> dict[str, float]:
        out = {}
        for spec, m in zip(self.models, self.models_, strict=True):
            out[f"{spec['name']}/prediction"] = m.prediction
            out[f"{spec['name']}/residual"] = m.residual
            out[f"{spec['name']}/parameter_change"] = m.change
        return out

    # -- calibration -------------------------------------------------------------------

    def fit(self, segments: list[Sampled]) -> FfRlsMonitor:
        names = [m["name"] for m in self.models]
        for attr in ("theta0_", "P0_", "gamma_r_"):
            self.__dict__.pop(attr, None)
        finals = [self._calibration_run(s, final=True) for s in segments]
        self.theta0_ = {n: np.mean([f[n][0] for f in finals], axis=0) for n in names}
        self.P0_ = {n: np.mean([f[n][1] for f in finals], axis=0) for n in names}

        runs = [self._calibration_run(s, final=False) for s in segments]
        self.res_mean_, self.res_var_, self.dtheta_cov_, self.dtheta_info_ = {}, {}, {}, {}
        self.gamma_r_, self.gamma_r_joint_, self.gamma_theta_joint_ = {}, {}, {}
        for n in names:
            eps = [r[n][0] for r in runs]
            dtheta = np.vstack([r[n][1] for r in runs])
            self.res_mean_[n] = float(np.mean(np.concatenate(eps)))
            self.res_var_[n] = float(np.var(np.concatenate(eps)))
            self.dtheta_cov_[n] = np.cov(dtheta, rowvar=False)
            self.dtheta_info_[n] = np.linalg.pinv(self.dtheta_cov_[n])
            g = np.concatenate([self._glrt_run(run, n) for run in eps])
            t = np.einsum("ij,jk,ik->i", dtheta, self.dtheta_info_[n], dtheta)
            self.gamma_r_[n] = empirical_threshold(g, self.false_alarm)
            self.gamma_r_joint_[n], self.gamma_theta_joint_[n] = joint_thresholds(
                g, t, self.false_alarm)
        return self

    def _glrt_run(self, eps: np.ndarray, name: str) -> np.ndarray:
        return glrt_statistic(eps - self.res_mean_[name], self._window(), self.res_var_[name])

    def _calibration_run(self, s: Sampled, final: bool) -> dict:
        """Per model: final (theta, P) from theta = 0 (``final``), else the armed
        (residuals, parameter changes) from the a-priori values; no freezing."""
        out = {}
        for spec in self.models:
            r = self._kernel_run(s, spec, from_prior=not final, freeze=False)
            ok = np.isfinite(r["g"])
            out[spec["name"]] = ((r["theta"], r["P"]) if final
                                 else (r["eps"][ok], r["dtheta"][ok]))
        return out

    def _kernel_run(self, s: Sampled, spec: dict, from_prior: bool, freeze: bool,
                    start: int = 0, kernel: tuple | None = None) -> dict:
        """One model over the steps ``start:`` of ``s`` through
        :func:`~.kernels.ffrls_advance`: from the fitted prior (``from_prior``) or from
        theta = 0, P = p0 I, or from ``kernel``, the (counts, state) it ended a run
        with (``r["kernel"]``, copied); with or without freezing."""
        cols = {n: i for i, n in enumerate(s.names)}
        x = s.x[start:]
        u = normalise_inputs(x[:, [cols[c] for c in spec["inputs"]]], spec["inputs"])
        y = np.ascontiguousarray(x[:, cols[spec["output"]]])
        n_par = len(spec["inputs"]) + bool(spec["autoregressive"]) + 1
        name = spec["name"]
        m, n = self._window(), x.shape[0]
        config = np.zeros(len(FfrlsConfig))
        counts = np.zeros(len(FfrlsCount), dtype=np.int64)
        state = np.zeros(kernels.ffrls_state_size(n_par, m))
        theta, P, _, _, y_prev, _, _ = kernels.ffrls_views.py_func(state, n_par, m)
        y_prev[0] = np.nan
        if from_prior:
            theta[:], P[:] = self.theta0_[name], self.P0_[name]
            max_trace = self.max_trace_ratio * float(np.trace(P))
        else:
            P[:], max_trace = np.eye(n_par) * self.p0, np.inf
        if kernel is not None:
            counts[:], state[:] = kernel
        fitted = hasattr(self, "gamma_r_")
        config[[FfrlsConfig.AR, FfrlsConfig.LAM, FfrlsConfig.MAX_TRACE, FfrlsConfig.FREEZE,
                FfrlsConfig.M]] = spec["autoregressive"], self.forgetting, max_trace, freeze, m
        config[[FfrlsConfig.RES_MEAN, FfrlsConfig.SIGMA2, FfrlsConfig.GAMMA_R_JOINT,
                FfrlsConfig.GAMMA_THETA_JOINT]] = (
            (self.res_mean_[name], self.res_var_[name], self.gamma_r_joint_[name],
             self.gamma_theta_joint_[name]) if fitted else (0.0, 1.0, 1.0, 1.0))
        out = np.empty((len(FfrlsOut), n))
        r = {"dtheta": np.empty((n, n_par))}
        kernels.ffrls_advance(np.ascontiguousarray(u), y, config, counts, state,
                              self.dtheta_info_[name] if fitted else np.zeros((n_par, n_par)),
                              out, r["dtheta"])
        r.update({row.name.lower(): out[row] for row in FfrlsOut})
        r["theta"], r["P"], r["y"] = theta.copy(), P.copy(), y
        r["kernel"] = counts, state
        return r

    def fitted(self) -> dict:
        self._check_fitted("gamma_r_")
        return {n: {"theta0": self.theta0_[n].tolist(),
                    "trace_cov0": float(np.trace(self.P0_[n])),
                    "residual_mean": self.res_mean_[n], "residual_var": self.res_var_[n],
                    "gamma_r": self.gamma_r_[n], "gamma_r_joint": self.gamma_r_joint_[n],
                    "gamma_theta_joint": self.gamma_theta_joint_[n]}
                for n in self.theta0_}

    # -- streaming ---------------------------------------------------------------------

    def _window(self) -> int:
        return max(1, round(self.window_s * self.rate_hz))

    def _reset_models(self, theta0: bool) -> None:
        if not 0.0 < self.forgetting <= 1.0:
            raise ValueError(f"forgetting must be in (0, 1], got {self.forgetting}")
        cols = {s: i for i, s in enumerate(self.signals())}
        self.models_ = [_Model(self, spec, cols) for spec in self.models]
        for spec, m in zip(self.models, self.models_, strict=True):
            if theta0:
                m.rls.reset(self.theta0_[spec["name"]], self.P0_[spec["name"]])
            else:
                m.rls.reset()

    def reset(self) -> FfRlsMonitor:
        self._check_fitted("gamma_r_")
        self._reset_models(theta0=True)
        self.glrt_ = [WindowedGlrt(self._window(), self.res_var_[m["name"]]).reset()
                      for m in self.models]
        return self

    def _model_step(self, m: _Model, x: np.ndarray):
        u = list(normalise_inputs(x[m.u_cols], m.u_names))
        y = float(x[m.y_col])
        ar = [m.y_prev] if m.ar else []
        m.y_prev = y
        m.prediction = m.residual = m.change = math.nan
        if m.ar and not math.isfinite(ar[0]):
            return math.nan, None
        phi = np.array([*u, *ar, 1.0])
        if m.frozen:
            eps = y - phi @ m.rls.theta_                   # (14) with theta held
        else:
            eps = m.rls.update(phi, y)                     # (14)-(16)
        m.prediction, m.residual = y - eps, eps
        m.thetas.append(m.rls.theta_.copy())          # theta_ changes in place
        if len(m.thetas) <= self._window():
            return eps, None
        return eps, m.thetas[-1] - m.thetas[0]             # theta(k) - theta(k - M)

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        score = np.full(2 * len(self.models), np.nan)
        for j, (spec, m) in enumerate(zip(self.models, self.models_, strict=True)):
            n = spec["name"]
            eps, dtheta = self._model_step(m, x)
            if dtheta is None:
                continue
            g = self.glrt_[j].update(eps - self.res_mean_[n])
            t = float(dtheta @ self.dtheta_info_[n] @ dtheta)  # T = dtheta' Sigma^-1 dtheta
            m.change = t
            m.frozen = g > self.gamma_r_joint_[n]      # stop adapting while residual test is up
            joint = min(g / self.gamma_r_joint_[n], t / self.gamma_theta_joint_[n])
            score[2 * j], score[2 * j + 1] = g, joint
        return score

    def snapshot(self) -> dict:
        """Per model, the kernel's counters and state after the last :meth:`run`."""
        return {n: (c.copy(), st.copy()) for n, (c, st) in self.kernel_.items()}

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: dict | None = None) -> tuple[np.ndarray, dict]:
        """The compiled form of :meth:`update` over ``s`` (equal to rounding); continued
        from a :meth:`snapshot` at step ``start``, over the steps from there."""
        self.reset()
        start = 0 if state is None else start
        score, kept, self.kernel_ = [], {}, {}
        for spec in self.models:
            r = self._kernel_run(s, spec, from_prior=True, freeze=True, start=start,
                                 kernel=None if state is None else state[spec["name"]])
            self.kernel_[spec["name"]] = r["kernel"]
            score += [r["g"], r["joint"]]
            if probes:
                kept[f"{spec['name']}/prediction"] = r["y"] - r["eps"]
                kept[f"{spec['name']}/residual"] = r["eps"]
                kept[f"{spec['name']}/parameter_change"] = r["t"]
        return np.column_stack(score), kept
