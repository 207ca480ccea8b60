r"""GLRT on ARX residuals with a data-driven threshold (Hansen, Blanke, Adrian 2014).

For each input/output pair of the RLS-ARX detector (commanded roll and pitch against
the measured angle and its error) a residual :math:`r(k)` is generated, centred and
scaled by its fault-free mean :math:`\mu_0` and variance :math:`\sigma_0^2`, and fed to
the windowed GLRT of :mod:`.glrt`; the pair alarms when :math:`g(k) > \gamma`.

Residual generators (``residuals``):

``"arx"``
    A fixed ARX model per pair, :math:`r(k) = y(k) - \phi^T(k)\hat\theta`, with
    :math:`\hat\theta` fitted by least squares on the fault-free training segments.
    The paper's self-tuning residual generator, frozen after training.
``"rls"``
    The RLS-ARX prediction error :math:`\hat e(k)` of :mod:`.rls_arx_zscore`, from
    the step its model is stable on; the GLRT replaces the z-score test.

Thresholds (``threshold``):

``"empirical"``
    The paper's: the :math:`1-P_F` quantile of :math:`g` on the training segments,
    per pair. :math:`P_F = 5\cdot10^{-4}` is the paper's.
``"chi2"``
    :math:`\tfrac12 F^{-1}_{\chi^2_1}(1-P_F)`, which assumes white Gaussian residuals;
    a named variant to show what ignoring their correlation costs.

Choices the paper leaves open (none fitted to scores): ``window_s = 2`` seconds for
:math:`M`, i.e. 50 samples at 25 Hz and about five refreshes of the measured angle
(~2.5 Hz), the fewest that make a mean shift distinguishable from one held outlier;
the ARX orders are those of the RLS-ARX detector (:math:`n_a = 1`, one second of
inputs) so both residual generators see the same regressors.
"""

from __future__ import annotations

import numpy as np

from alfa_bench.data import Sampled

from . import kernels
from .arx import ArxRegressor, arx_regressors, fit_arx
from .base import PairDetector
from .glrt import chi2_threshold, empirical_threshold, glrt_statistic
from .rls_arx_zscore import DEFAULT_PAIRS, RlsArxZscore

__all__ = ["GlrtResiduals"]

_RESIDUALS = ("arx", "rls")
_THRESHOLDS = ("empirical", "chi2")


class GlrtResiduals(PairDetector):
    """Windowed GLRT on per-pair ARX residuals; calibrated on fault-free segments.

    Parameters
    ----------
    pairs : sequence of dict
        As for :class:`~.rls_arx_zscore.RlsArxZscore`.
    residuals : {"arx", "rls"}
    threshold : {"empirical", "chi2"}
    false_alarm : float
        :math:`P_F` per sample.
    window_s : float
        GLRT window; :math:`M` = round(window x rate).
    rate_hz, na, input_window_s : float, int, float
        Grid and ARX orders, as for RLS-ARX.
    p0, warmup_samples, eps, stable_s : float, int, float, float
        RLS-ARX settings, used when ``residuals = "rls"``.

    Attributes
    ----------
    theta_ : list of ndarray
        Fitted ARX parameters per pair (``"arx"`` only).
    mean_, var_ : ndarray
        Fault-free residual mean and variance per pair.
    threshold_ : ndarray
        :math:`\\gamma` per pair.
    glrt_buf_, glrt_count_ : ndarray
        Per pair, the last :math:`M` centred residuals (newest first) and their count:
        the state of :func:`~.kernels.glrt_advance`.
    residual_, output_ : ndarray
        The last residual (NaN while not armed) and output per pair.
    """

    family = "statistical test"

    calibrated = True

    def __init__(self, pairs=DEFAULT_PAIRS, residuals="arx", threshold="empirical",
                 false_alarm=5e-4, window_s=2.0, rate_hz=25.0, na=1, input_window_s=1.0,
                 p0=1e6, warmup_samples=200, eps=1e-3, stable_s=1.0):
        self.pairs = pairs
        self.residuals = residuals
        self.threshold = threshold
        self.false_alarm = false_alarm
        self.window_s = window_s
        self.rate_hz = rate_hz
        self.na = na
        self.input_window_s = input_window_s
        self.p0 = p0
        self.warmup_samples = warmup_samples
        self.eps = eps
        self.stable_s = stable_s

    def thresholds(self) -> np.ndarray:
        self._check_fitted("threshold_")
        return self.threshold_.copy()

    def probes(self) -> dict[str, float]:
        out = {}
        for j, p in enumerate(self.pairs):
            out[f"{p['name']}/prediction"] = self.output_[j] - self.residual_[j]
            out[f"{p['name']}/residual"] = self.residual_[j]
        return out

    # -- calibration -------------------------------------------------------------------

    def fit(self, segments: list[Sampled]) -> GlrtResiduals:
        self._validate()
        for attr in ("theta_", "mean_", "var_", "threshold_"):
            self.__dict__.pop(attr, None)
        cols = {s: i for i, s in enumerate(self.signals())}
        if self.residuals == "arx":
            self.theta_ = [fit_arx([(s.x[:, cols[p["input"]]], s.x[:, cols[p["output"]]])
                                    for s in segments], self.na, self._nb())
                           for p in self.pairs]
        r = [self._residual_run(s) for s in segments]
        pooled = np.vstack(r)
        self.mean_ = np.nanmean(pooled, axis=0)
        self.var_ = np.nanvar(pooled, axis=0)
        if self.threshold == "chi2":
            self.threshold_ = np.full(len(self.pairs), chi2_threshold(self.false_alarm))
            return self
        window = self._window()
        self.threshold_ = np.array([empirical_threshold(np.concatenate([
            glrt_statistic(ri[np.isfinite(ri[:, j]), j] - self.mean_[j], window, self.var_[j])
            for ri in r]), self.false_alarm) for j in range(len(self.pairs))])
        return self

    def fitted(self) -> dict:
        self._check_fitted("threshold_")
        out = {"residual_mean": self.mean_.tolist(), "residual_var": self.var_.tolist(),
               "threshold": self.threshold_.tolist()}
        if self.residuals == "arx":
            out["arx_theta"] = [t.tolist() for t in self.theta_]
        return out

    def _residual_run(self, s: Sampled, start: int = 0, rls: dict | None = None
                      ) -> np.ndarray:
        """Residuals over the steps ``start:`` of a segment, NaN where not armed: what
        :meth:`update` sees. The RLS residuals continue from the recursion's
        :meth:`~.rls_arx_zscore.RlsArxZscore.snapshot` ``rls`` (from the start if None);
        the fixed ARX ones read the regressors' history again from ``s``."""
        if self.residuals == "arx":
            armed = max(self.na, self._nb() - 1)
            first = max(0, start - armed)
            seg = s.since(first)
            r = np.full((seg.t.size, len(self.pairs)), np.nan)
            for j, (iu, iy) in enumerate(self._cols()):
                phi, y = arx_regressors(seg.x[:, iu], seg.x[:, iy], self.na, self._nb())
                r[armed:, j] = y - phi @ self.theta_[j]        # r = y - phi' theta
            return r[start - first:]
        if rls is None:
            self._reset_residuals()
        else:
            self.rls_arx_.restore(rls)
        return self.rls_arx_.advance(s.x[start:], s.fresh[start:])["judged"]

    # -- streaming ---------------------------------------------------------------------

    def reset(self) -> GlrtResiduals:
        self._validate()
        self._check_fitted("threshold_")
        self._reset_residuals()
        self._reset_glrt()
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        return self._glrt_step(self._residual_step(x, fresh))

    def snapshot(self) -> dict:
        """The GLRT windows, and the RLS recursion's state where residuals are ``rls``."""
        return {"glrt": (self.glrt_buf_.copy(), self.glrt_count_.copy()),
                "rls": self.rls_arx_.snapshot() if self.residuals == "rls" else None}

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: dict | None = None) -> tuple[np.ndarray, dict]:
        """The batch form: residuals of the whole segment at once, then the GLRT kernel;
        equal to streaming to rounding. Continued from a :meth:`snapshot` at step
        ``start``, it runs over the steps from there."""
        self.reset()
        if state is None:
            start = 0
        else:
            self.glrt_buf_[:], self.glrt_count_[:] = state["glrt"]
        r = self._residual_run(s, start, None if state is None else state["rls"])
        g = np.column_stack([self._glrt_run(j, r[:, j]) for j in range(len(self.pairs))])
        kept = {}
        if probes:
            for j, (p, (_, iy)) in enumerate(zip(self.pairs, self.cols_, strict=True)):
                kept[f"{p['name']}/prediction"] = s.x[start:, iy] - r[:, j]
                kept[f"{p['name']}/residual"] = r[:, j]
        return g, kept

    def _validate(self) -> None:
        if self.residuals not in _RESIDUALS:
            raise ValueError(f"residuals must be one of {_RESIDUALS}, got {self.residuals!r}")
        if self.threshold not in _THRESHOLDS:
            raise ValueError(f"threshold must be one of {_THRESHOLDS}, got {self.threshold!r}")

    def _nb(self) -> int:
        return max(1, round(self.input_window_s * self.rate_hz))

    def _window(self) -> int:
        return max(1, round(self.window_s * self.rate_hz))

    def _cols(self) -> list[tuple[int, int]]:
        cols = {s: i for i, s in enumerate(self.signals())}
        return [(cols[p["input"]], cols[p["output"]]) for p in self.pairs]

    def _reset_residuals(self) -> None:
        self.cols_ = self._cols()
        if self.residuals == "arx":
            self.arx_ = [ArxRegressor(self.na, self._nb()).reset() for _ in self.pairs]
        else:
            self.rls_arx_ = RlsArxZscore(
                pairs=self.pairs, rate_hz=self.rate_hz, na=self.na,
                input_window_s=self.input_window_s, p0=self.p0,
                warmup_samples=self.warmup_samples, eps=self.eps,
                stable_s=self.stable_s).reset()
        self.residual_ = np.full(len(self.pairs), np.nan)
        self.output_ = np.full(len(self.pairs), np.nan)

    def _residual_step(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        self.output_ = np.array([x[iy] for _, iy in self.cols_], dtype=float)
        if self.residuals == "rls":                    # e = y - phi' theta(k-1), once stable
            self.residual_ = self.rls_arx_.advance(x[None, :], fresh[None, :])["judged"][0]
            return self.residual_
        r = np.full(len(self.pairs), np.nan)
        for j, (iu, iy) in enumerate(self.cols_):
            reg = self.arx_[j]
            reg.push(float(x[iu]))
            if reg.ready():
                r[j] = x[iy] - reg.phi() @ self.theta_[j]  # r = y - phi' theta
            reg.push_output(float(x[iy]))
        self.residual_ = r
        return r

    def _reset_glrt(self) -> None:
        if not np.all(self.var_ > 0):
            raise ValueError(f"GLRT residual variances must be > 0, got {self.var_}")
        self.glrt_buf_ = np.zeros((len(self.pairs), self._window()))
        self.glrt_count_ = np.zeros((len(self.pairs), 1), dtype=np.int64)

    def _glrt_run(self, j: int, r: np.ndarray) -> np.ndarray:
        g = np.empty(r.size)
        kernels.glrt_advance(r - self.mean_[j], self.glrt_buf_[j], self.glrt_count_[j],
                             float(self.var_[j]), g)   # x = r - mu0
        return g

    def _glrt_step(self, r: np.ndarray) -> np.ndarray:
        return np.array([self._glrt_run(j, r[j:j + 1])[0] for j in range(len(self.pairs))])
