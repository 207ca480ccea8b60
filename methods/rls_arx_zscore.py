r"""RLS-ARX z-score detector of Keipour, Mousaei and Scherer (ICRA 2019).

For each input/output pair :math:`(u, y)` an ARX model (eq. 3)

.. math::

    y(k) = \sum_{i=1}^{n_a} a_i\, y(k-i) + \sum_{j=0}^{n_b-1} b_j\, u(k-j) + n(k)

is estimated online by RLS (eqs. 4-7 of :mod:`.rls`) from
:math:`\hat\theta = 0` and a large diagonal covariance. The model is *stable* once
:math:`\|K(k)\hat e(k)\|_\infty < \epsilon` has held for ``stable_s`` seconds, and
not before ``warmup_samples`` steps. From then on the prediction error's mean and
variance are tracked by Welford's method (eq. 8); once the variance is stable
too (relative change per update below ``var_rtol`` for ``var_stable_s`` seconds),
each new error gets the z-score

.. math::

    z(k) = |\hat e(k) - \bar e_{n}| / s_{n},

computed with the statistics *before* :math:`\hat e(k)` joins them (so an outlier
does not shrink its own score), and the pair alarms when :math:`z(k) > 4.5`.
Both stability flags latch. A flight alarms when any pair alarms.

The recursion runs in the compiled kernel :func:`~.kernels.rls_arx_advance`, which
streaming (:meth:`RlsArxZscore.update`, one step) and batch runs
(:meth:`RlsArxZscore.run`, a flight) share.

Parameters the paper states, kept as stated: the pairs (commanded roll and pitch
against the measured angle and against the error measured - commanded); z = 4.5;
RLS from zero parameters with a "very large" diagonal covariance (``p0``);
"about 25 Hz" signals, "200 samples" (8 s) to stabilise, and the inputs of "the
last second (25 samples)", hence ``rate_hz = 25``, ``warmup_samples = 200`` and
``input_window_s = 1`` (:math:`n_b = 25`).

Choices the paper leaves open, and why these values (none was fitted to scores):

``na = 1``
    The paper gives no output order. The autopilot's attitude loop is, to first
    order, a lag from command to angle; one autoregressive term is the smallest
    that makes the model ARX rather than FIR, and the 1 s input window carries
    the remaining memory, as the paper's emphasis on input samples suggests.
``eps = 1e-3``, ``stable_s = 1.0``
    "a small positive number" held "for some time": a per-step change of 0.1 %
    of a unit gain (ARX coefficients are dimensionless), held for one input
    window.
``var_rtol = 0.01``, ``var_stable_s = 1.0``
    "variance is also stable": relative change below 1 % per update for one
    second; for a stationary error that needs roughly a hundred samples, the
    least for which a 4.5-sigma tail is meaningful.
``rate_hz = 25`` with a causal hold
    ALFA's ``nav_info`` rows come at ~19.5 Hz; on a 25 Hz grid about one value
    in four is a repeat. No interpolation, which would look ahead.
``repeated_samples = "hold"``
    The paper treats every sample of its stream as a measurement, so the faithful
    setting does too. In ALFA the *measured* angle is refreshed only at ~2.5 Hz
    (held for ~8 rows), so the error is near zero while held and jumps at each
    refresh: heavy-tailed, not the Gaussian the z-score assumes. ``"fresh"``
    updates a pair only when its output carries a new measurement; it is a
    named variant, not the faithful method.
"""

from __future__ import annotations

import numpy as np

from alfa_bench.data import Sampled

from . import kernels
from .base import PairDetector
from .kernels import ArxConfig, ArxCount, ArxOut, ArxStat

__all__ = ["DEFAULT_PAIRS", "RlsArxZscore"]

DEFAULT_PAIRS = (
    {"name": "roll", "input": "roll_cmd", "output": "roll"},
    {"name": "roll_error", "input": "roll_cmd", "output": "roll_error"},
    {"name": "pitch", "input": "pitch_cmd", "output": "pitch"},
    {"name": "pitch_error", "input": "pitch_cmd", "output": "pitch_error"},
)

_REPEATED = ("hold", "fresh")


class _Pair:
    """State of one input/output pair: the ``config``, ``counts`` and ``state`` arrays
    :func:`~.kernels.rls_arx_advance` advances, and the named views of ``state``
    (:func:`~.kernels.arx_views`)."""

    def __init__(self, det: RlsArxZscore, u_col: int, y_col: int):
        self.u_col, self.y_col = u_col, y_col
        na, nb = det.na, max(1, round(det.input_window_s * det.rate_hz))
        self.config = np.zeros(len(ArxConfig))
        self.config[[ArxConfig.NA, ArxConfig.NB, ArxConfig.WARMUP, ArxConfig.EPS,
                     ArxConfig.STABLE_STEPS, ArxConfig.VAR_RTOL, ArxConfig.VAR_STEPS,
                     ArxConfig.FRESH_ONLY]] = (
            na, nb, det.warmup_samples, det.eps, round(det.stable_s * det.rate_hz),
            det.var_rtol, round(det.var_stable_s * det.rate_hz),
            det.repeated_samples == "fresh")
        self.counts = np.zeros(len(ArxCount), dtype=np.int64)
        self.counts[[ArxCount.STREAK_FROM, ArxCount.VAR_FROM]] = -1
        self.state = np.zeros(kernels.arx_state_size(na, nb))
        (self.theta, self.P, self.u_hist, self.y_hist, self.phi, self.P_phi, self.K,
         self.stats) = kernels.arx_views.py_func(self.state, na, nb)
        self.P[:] = np.eye(na + nb) * det.p0           # P(0) = p0 I, theta(0) = 0
        self.stats[ArxStat.LAST_VAR] = np.nan

    @property
    def updates(self) -> int:
        """RLS updates made."""
        return int(self.counts[ArxCount.UPDATES])

    @property
    def model_stable(self) -> bool:
        return bool(self.counts[ArxCount.MODEL_STABLE])

    @property
    def var_stable(self) -> bool:
        return bool(self.counts[ArxCount.VAR_STABLE])


class RlsArxZscore(PairDetector):
    """RLS-ARX z-score detector; see the module docstring for every parameter.

    Parameters
    ----------
    pairs : sequence of dict
        ``{"name", "input", "output"}``, signal names from
        :data:`alfa_bench.data.SIGNALS`.
    rate_hz : float
    na : int
        ARX output order :math:`n_a`.
    input_window_s : float
        Seconds of inputs in the regressor; :math:`n_b` = round(window x rate).
    p0 : float
        Initial RLS covariance :math:`P(0) = p_0 I`.
    warmup_samples : int
        Steps before a model may be declared stable.
    eps, stable_s : float
        Model stability: :math:`\\|K\\hat e\\|_\\infty < \\epsilon` for ``stable_s``.
    var_rtol, var_stable_s : float
        Variance stability.
    z_threshold : float
    repeated_samples : {"hold", "fresh"}

    Attributes
    ----------
    pairs_ : list
        Per-pair state: ``theta``, ``P``, the regressor histories, Welford's
        ``stats``, flags ``model_stable`` and ``var_stable``.
    last_ : dict of ndarray
        Per pair, the outputs of the last step (see :meth:`advance`).
    """

    family = "model residuals"

    def __init__(self, pairs=DEFAULT_PAIRS, rate_hz=25.0, na=1, input_window_s=1.0,
                 p0=1e6, warmup_samples=200, eps=1e-3, stable_s=1.0, var_rtol=0.01,
                 var_stable_s=1.0, z_threshold=4.5, repeated_samples="hold"):
        self.pairs = pairs
        self.rate_hz = rate_hz
        self.na = na
        self.input_window_s = input_window_s
        self.p0 = p0
        self.warmup_samples = warmup_samples
        self.eps = eps
        self.stable_s = stable_s
        self.var_rtol = var_rtol
        self.var_stable_s = var_stable_s
        self.z_threshold = z_threshold
        self.repeated_samples = repeated_samples

    def thresholds(self) -> np.ndarray:
        return np.full(len(self.pairs), float(self.z_threshold))

    def probes(self) -> dict[str, float]:
        return _probes(self.pairs, {k: v[-1] for k, v in self.last_.items()})

    def reset(self) -> RlsArxZscore:
        if self.repeated_samples not in _REPEATED:
            raise ValueError(f"repeated_samples must be one of {_REPEATED}, "
                             f"got {self.repeated_samples!r}")
        if self.na < 0:
            raise ValueError(f"na must be >= 0, got {self.na}")
        cols = {s: i for i, s in enumerate(self.signals())}
        self.pairs_ = [_Pair(self, cols[p["input"]], cols[p["output"]]) for p in self.pairs]
        self.last_ = {k: np.full((1, len(self.pairs)), np.nan) for k in _OUTPUTS}
        return self

    def advance(self, x: np.ndarray, fresh: np.ndarray) -> dict[str, np.ndarray]:
        """Consume the steps of ``x`` and ``fresh`` (shape (n, m)); return per step and
        pair (shape (n, pairs)) ``z``, ``prediction`` and ``residual`` of an RLS update,
        and ``judged``, the residual of a pair whose model was already stable."""
        x = np.asarray(x, dtype=float)
        n = x.shape[0]
        out = np.empty((len(self.pairs_), len(ArxOut), n))
        for j, p in enumerate(self.pairs_):
            kernels.rls_arx_advance(
                np.ascontiguousarray(x[:, p.u_col]), np.ascontiguousarray(x[:, p.y_col]),
                np.ascontiguousarray(fresh[:, p.y_col]), p.config, p.counts, p.state, out[j])
        out = {k: out[:, row].T for k, row in zip(_OUTPUTS, ArxOut, strict=True)}
        self.last_ = {k: v[-1:] for k, v in out.items()}
        return out

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        return self.advance(x[None, :], fresh[None, :])["z"][0]

    def snapshot(self) -> dict:
        """Each pair's counters and state array, and the last step's outputs."""
        return {"pairs": [(p.counts.copy(), p.state.copy()) for p in self.pairs_],
                "last": {k: v.copy() for k, v in self.last_.items()}}

    def restore(self, state: dict) -> RlsArxZscore:
        """Reset, then take the pairs' state from a :meth:`snapshot` (copied, so that
        the snapshot serves again); the views of each state array stay its views."""
        self.reset()
        for p, (counts, arrays) in zip(self.pairs_, state["pairs"], strict=True):
            p.counts[:], p.state[:] = counts, arrays
        self.last_ = {k: v.copy() for k, v in state["last"].items()}
        return self

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: dict | None = None) -> tuple[np.ndarray, dict]:
        if state is None:
            self.reset()
            start = 0
        else:
            self.restore(state)
        out = self.advance(s.x[start:], s.fresh[start:])
        kept = ({name: out[kind][:, j] for name, (kind, j) in _probe_index(self.pairs).items()}
                if probes else {})
        return out["z"], kept


_OUTPUTS = tuple(row.name.lower() for row in ArxOut)


def _probe_index(pairs) -> dict[str, tuple[str, int]]:
    return {f"{p['name']}/{kind}": (kind, j) for j, p in enumerate(pairs)
            for kind in ("prediction", "residual")}


def _probes(pairs, last: dict[str, np.ndarray]) -> dict[str, float]:
    return {name: float(last[kind][j]) for name, (kind, j) in _probe_index(pairs).items()}
