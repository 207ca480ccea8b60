r"""Kalman-filter residuals from an OKID-identified observer (Heredia and Ollero, 2011).

A bank of output estimators (Sec. 4.1): one per measured output, each driven by all
the inputs and by that output alone, so a fault in one sensor moves only its own
residual. Each estimator's model and gain :math:`(A, B, C, D, L)` are identified by
OKID/ERA (:mod:`.okid`) from the fault-free training segments: no noise covariance is
guessed. It runs as filterpy's :class:`~filterpy.kalman.KalmanFilter` in steady state
with the filter gain :math:`K = A^{-1}L` (filterpy updates, then predicts; the
identified :math:`L` is the predictor's gain, :math:`L = AK`):

.. math::

    e(k) &= y(k) - D u(k) - C\hat x(k|k-1)          && \text{innovation}\\
    \hat x(k|k) &= \hat x(k|k-1) + K e(k)\\
    \hat x(k+1|k) &= A\hat x(k|k) + B u(k)

The residual is the normalised innovation squared
:math:`\nu(k) = (e(k) - \mu_0)^2 / s_0`, with :math:`\mu_0, s_0` the innovation's
fault-free mean and variance, and a sensor alarms when :math:`\nu(k)` passes the
threshold, read (as for the GLRT) as the :math:`1 - P_F` quantile of :math:`\nu` on
the training segments. The paper's residual is a weighted squared output error with
thresholds "adjusted to not get false positives"; reading them from fault-free data at
a stated :math:`P_F` is that adjustment made reproducible.

Choices the paper leaves open (none fitted to scores): the inputs and outputs of the
RLS-ARX detector (commanded and measured roll and pitch) on its 25 Hz grid;
``lags_s = 1`` (25 observer Markov parameters, the RLS-ARX input window);
``order = 4``, two states per attitude axis, a first-order command lag plus the
autopilot's integral action; the estimator arms after ``lags`` steps, when the
deadbeat-like observer has forgotten its zero initial state.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from alfa_bench.data import Sampled

from . import kernels
from .base import CalibrationError, Detector
from .glrt import empirical_threshold
from .okid import OkidModel, okid

if TYPE_CHECKING:
    from filterpy.kalman import KalmanFilter

__all__ = ["KalmanOkid"]


class KalmanOkid(Detector):
    """Bank of OKID Kalman filters, one per output, with NIS residuals.

    Parameters
    ----------
    inputs, outputs : sequence of str
        Signal names from :data:`alfa_bench.data.SIGNALS`.
    rate_hz : float
    lags_s : float
        Observer Markov parameters :math:`p` = round(lags x rate).
    order : int
        State dimension of each identified model.
    false_alarm : float
        :math:`P_F` per sample.

    Attributes
    ----------
    models_ : list of :class:`~.okid.OkidModel`
        One per output.
    innovation_mean_, innovation_var_, threshold_ : ndarray
        Per output.
    filters_ : list of :class:`~filterpy.kalman.KalmanFilter`
        Per output; ``y`` holds the last innovation, ``K`` the gain.
    x_ : list of ndarray
        Per output, the state estimate :math:`\\hat x` after the last batch :meth:`run`
        (what :meth:`snapshot` copies).
    output_, innovation_ : ndarray
        The last output and innovation per output (NaN while not armed).
    """

    family = "model residuals"

    calibrated = True

    def __init__(self, inputs=("roll_cmd", "pitch_cmd"), outputs=("roll", "pitch"),
                 rate_hz=25.0, lags_s=1.0, order=4, false_alarm=5e-4):
        self.inputs = inputs
        self.outputs = outputs
        self.rate_hz = rate_hz
        self.lags_s = lags_s
        self.order = order
        self.false_alarm = false_alarm

    def signals(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys((*self.inputs, *self.outputs)))

    def channels(self) -> tuple[str, ...]:
        return tuple(self.outputs)

    def channel_outputs(self) -> tuple[str, ...]:
        return tuple(self.outputs)

    def thresholds(self) -> np.ndarray:
        self._check_fitted("threshold_")
        return self.threshold_.copy()

    def probes(self) -> dict[str, float]:
        out = {}
        for i, name in enumerate(self.outputs):
            out[f"{name}/prediction"] = self.output_[i] - self.innovation_[i]
            out[f"{name}/innovation"] = self.innovation_[i]
        return out

    def _lags(self) -> int:
        return max(1, round(self.lags_s * self.rate_hz))

    def _split(self, s: Sampled) -> tuple[np.ndarray, np.ndarray]:
        cols = {n: i for i, n in enumerate(s.names)}
        return (s.x[:, [cols[n] for n in self.inputs]],
                s.x[:, [cols[n] for n in self.outputs]])

    def fit(self, segments: list[Sampled]) -> KalmanOkid:
        for attr in ("models_", "threshold_"):
            self.__dict__.pop(attr, None)
        data = [self._split(s) for s in segments]
        models = [okid([(u, y[:, [i]]) for u, y in data], self._lags(), self.order)
                  for i in range(len(self.outputs))]
        for out, m in zip(self.outputs, models, strict=True):
            if not np.allclose(m.A @ np.linalg.solve(m.A, m.L), m.L):
                raise CalibrationError(f"OKID model of {out!r} has a singular A: no filter gain")
        self.models_ = models
        runs = [self._innovations(s, self._start_states()) for s in segments]
        e = np.vstack(runs)
        self.innovation_mean_ = np.nanmean(e, axis=0)
        self.innovation_var_ = np.nanvar(e, axis=0)
        nis = (e - self.innovation_mean_) ** 2 / self.innovation_var_
        self.threshold_ = np.array([empirical_threshold(nis[:, i], self.false_alarm)
                                    for i in range(len(self.outputs))])
        return self

    def fitted(self) -> dict:
        self._check_fitted("threshold_")
        return {out: {"A": m.A.tolist(), "B": m.B.tolist(), "C": m.C.tolist(),
                      "D": m.D.tolist(), "L": m.L.tolist(),
                      "hankel_sv": m.hankel_sv[:2 * self.order].tolist(),
                      "innovation_mean": float(self.innovation_mean_[i]),
                      "innovation_var": float(self.innovation_var_[i]),
                      "threshold": float(self.threshold_[i])}
                for i, (out, m) in enumerate(zip(self.outputs, self.models_, strict=True))}

    def _start_states(self) -> list[np.ndarray]:
        return [np.zeros(m.A.shape[0]) for m in self.models_]   # x(0) = 0, as the filters'

    def _innovations(self, s: Sampled, x: list[np.ndarray], start: int = 0) -> np.ndarray:
        """Innovations over the steps ``start:`` of a segment, from the filters' state
        estimates ``x`` (updated in place): the compiled form of the stepwise filterpy
        filters, equal to rounding."""
        u, y = self._split(s.since(start))
        e = np.empty((s.t.size - start, len(self.outputs)))
        for i, m in enumerate(self.models_):
            kernels.kalman_innovations(m.A, m.B, m.C, m.D, np.linalg.solve(m.A, m.L), u,
                                       np.ascontiguousarray(y[:, i]),
                                       max(0, self._lags() - start), x[i], e[:, i])
        return e

    @staticmethod
    def _filter(m: OkidModel) -> KalmanFilter:
        # filterpy imports scipy.stats (~0.5 s): only where a filter is made
        from filterpy.kalman import KalmanFilter

        kf = KalmanFilter(dim_x=m.A.shape[0], dim_z=1, dim_u=m.B.shape[1])
        kf.F, kf.B, kf.H = m.A, m.B, m.C
        kf.K = np.linalg.solve(m.A, m.L)                   # L = A K
        return kf

    def _reset_filters(self) -> None:
        self._check_fitted("models_")
        cols = {n: i for i, n in enumerate(self.signals())}
        self.u_cols_ = [cols[n] for n in self.inputs]
        self.y_cols_ = [cols[n] for n in self.outputs]
        self.filters_ = [self._filter(m) for m in self.models_]
        self.steps_ = 0
        self.output_ = np.full(len(self.outputs), np.nan)
        self.innovation_ = np.full(len(self.outputs), np.nan)

    def _innovation_step(self, x: np.ndarray) -> np.ndarray:
        u = x[self.u_cols_]
        e = np.full(len(self.outputs), np.nan)
        for i, (kf, m) in enumerate(zip(self.filters_, self.models_, strict=True)):
            kf.update_steadystate(x[self.y_cols_[i]] - m.D @ u)  # e = y - D u - C x
            if self.steps_ >= self._lags():
                e[i] = kf.y[0, 0]
            kf.predict_steadystate(u.reshape(-1, 1))       # x = A x + B u
        self.steps_ += 1
        self.output_, self.innovation_ = x[self.y_cols_], e
        return e

    def reset(self) -> KalmanOkid:
        self._check_fitted("threshold_")
        self._reset_filters()
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        e = self._innovation_step(x)
        return (e - self.innovation_mean_) ** 2 / self.innovation_var_  # nu = (e - mu)^2 / s

    def snapshot(self) -> list[np.ndarray]:
        """The filters' state estimates after the last :meth:`run`."""
        return [x.copy() for x in self.x_]

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: list[np.ndarray] | None = None) -> tuple[np.ndarray, dict]:
        """The batch form, through :func:`~.kernels.kalman_innovations`; continued from
        the state estimates of a :meth:`snapshot` at step ``start``."""
        self.reset()
        if state is None:
            start, self.x_ = 0, self._start_states()
        else:
            self.x_ = [x.copy() for x in state]
        e = self._innovations(s, self.x_, start)
        nis = (e - self.innovation_mean_) ** 2 / self.innovation_var_  # nu = (e - mu)^2 / s
        kept = {}
        if probes:
            _, y = self._split(s.since(start))
            for i, name in enumerate(self.outputs):
                kept[f"{name}/prediction"] = y[:, i] - e[:, i]
                kept[f"{name}/innovation"] = e[:, i]
        return nis, kept
