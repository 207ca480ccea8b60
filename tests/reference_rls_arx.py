"""The plain per-sample NumPy RLS and RLS-ARX z-score detector: the references for the
compiled ones.

This is the implementation the project ran before its detector core was compiled
(``methods/kernels.py``): per-sample Python with a NumPy RLS step, a deque regressor
and Welford's method. The tests hold the compiled detector to it,
and ``benchmarks/`` times both.
"""

from __future__ import annotations

import math

import numpy as np

from alfa_bench.methods.arx import ArxRegressor
from alfa_bench.methods.base import Detector
from alfa_bench.methods.rls import RecursiveLeastSquares
from alfa_bench.methods.rls_arx_zscore import RlsArxZscore


class PlainRecursiveLeastSquares(RecursiveLeastSquares):
    """:class:`~alfa_bench.methods.rls.RecursiveLeastSquares` with its step in plain
    NumPy (new arrays each step, no compiled kernel)."""

    def update(self, phi: np.ndarray, y: float) -> float:
        """One RLS step; returns the a-priori error :math:`\\hat e(k)`."""
        lam = self.forgetting
        e = y - phi @ self.theta_                      # (4) e = y - phi' theta
        P_phi = self.P_ @ phi
        K = P_phi / (lam + phi @ P_phi)                # (5) K = P phi / (lam + phi' P phi)
        step = K * e
        self.theta_ = self.theta_ + step               # (6) theta += K e
        P = (self.P_ - np.outer(K, P_phi)) / lam       # (7) P = (P - K phi' P) / lam
        P = 0.5 * (P + P.T)                            # keep P symmetric against round-off
        trace = np.trace(P)
        if trace > self.max_trace:
            P *= self.max_trace / trace                # tr P <= max_trace: no wind-up
        self.P_ = P
        self.error_, self.K_, self.step_ = float(e), K, step
        return self.error_


class Welford:
    """Numerically stable running mean and sample variance.

    Attributes
    ----------
    n_ : int
    mean_ : float
    m2_ : float
    """

    def __init__(self):
        self.reset()

    def reset(self) -> Welford:
        self.n_, self.mean_, self.m2_ = 0, 0.0, 0.0
        return self

    def update(self, x: float) -> None:
        self.n_ += 1
        delta = x - self.mean_
        self.mean_ += delta / self.n_         # mean_n = mean_{n-1} + (x - mean_{n-1}) / n
        self.m2_ += delta * (x - self.mean_)  # M2_n += (x - mean_{n-1})(x - mean_n)

    @property
    def variance(self) -> float:
        """Sample variance :math:`s_n^2`; NaN for fewer than two samples."""
        return self.m2_ / (self.n_ - 1) if self.n_ > 1 else math.nan


class _Pair:
    """State of one input/output pair."""

    def __init__(self, det: PlainRlsArxZscore, u_col: int, y_col: int):
        self.u_col, self.y_col = u_col, y_col
        nb = max(1, round(det.input_window_s * det.rate_hz))
        self.regressor = ArxRegressor(det.na, nb).reset()
        self.rls = PlainRecursiveLeastSquares(det.na + nb, det.p0).reset()
        self.welford = Welford()
        self.k = 0                    # grid steps seen
        self.updates = 0              # RLS updates made
        self.streak_from = None       # step where ||L e|| < eps began
        self.model_stable = False
        self.var_from = None          # step where the variance began to hold still
        self.var_stable = False
        self.last_var = math.nan
        self.prediction = math.nan    # y - e of the last RLS update at this step
        self.residual = math.nan


class PlainRlsArxZscore(RlsArxZscore):
    """:class:`~alfa_bench.methods.rls_arx_zscore.RlsArxZscore` stepped in plain
    per-sample Python and NumPy; same parameters.

    Attributes
    ----------
    pairs_ : list
        Per-pair state: ``rls`` (with ``theta_``, ``error_``, ``K_``),
        ``welford``, flags ``model_stable`` and ``var_stable``.
    """

    run = Detector.run                                 # step by step, not the compiled batch

    def probes(self) -> dict[str, float]:
        out = {}
        for spec, p in zip(self.pairs, self.pairs_, strict=True):
            out[f"{spec['name']}/prediction"] = p.prediction
            out[f"{spec['name']}/residual"] = p.residual
        return out

    def reset(self) -> PlainRlsArxZscore:
        super().reset()                                # validation
        self.stable_steps_ = round(self.stable_s * self.rate_hz)
        self.var_steps_ = round(self.var_stable_s * self.rate_hz)
        cols = {s: i for i, s in enumerate(self.signals())}
        self.pairs_ = [_Pair(self, cols[p["input"]], cols[p["output"]]) for p in self.pairs]
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        return np.array([self._step(pair, float(x[pair.u_col]), float(x[pair.y_col]),
                                    bool(fresh[pair.y_col])) for pair in self.pairs_])

    def _step(self, p: _Pair, u: float, y: float, fresh: bool) -> float:
        k = p.k
        p.k += 1
        p.prediction = p.residual = math.nan
        reg = p.regressor
        reg.push(u)
        if self.repeated_samples == "fresh" and not fresh:
            return math.nan
        if not reg.ready():
            reg.push_output(y)
            return math.nan
        e = p.rls.update(reg.phi(), y)
        p.prediction, p.residual = y - e, e
        reg.push_output(y)
        p.updates += 1

        if not p.model_stable:
            if np.max(np.abs(p.rls.step_)) < self.eps:
                p.streak_from = k if p.streak_from is None else p.streak_from
            else:
                p.streak_from = None
            p.model_stable = (p.streak_from is not None and p.updates >= self.warmup_samples
                              and k - p.streak_from >= self.stable_steps_)
            return math.nan

        w = p.welford
        z = math.nan
        if p.var_stable:
            dev = abs(e - w.mean_)
            z = dev / math.sqrt(w.variance) if w.variance > 0 else (math.inf if dev else 0.0)
        w.update(e)
        var = w.variance
        if not p.var_stable and w.n_ > 2:
            if abs(var - p.last_var) <= self.var_rtol * p.last_var:
                p.var_from = k if p.var_from is None else p.var_from
            else:
                p.var_from = None
            p.var_stable = p.var_from is not None and k - p.var_from >= self.var_steps_
        p.last_var = var
        return z
