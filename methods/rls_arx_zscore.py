r"""RLS-ARX z-score detector of Keipour, Mousaei and Scherer (ICRA 2019).

For each input/output pair :math:`(u, y)` an ARX model (eq. 3)

.. math::

    y(k) = \sum_{i=1}^{n_a} a_i\, y(k-i) + \sum_{j=0}^{n_b-1} b_j\, u(k-j) + n(k)

is estimated online by RLS (eqs. 4-7 of :mod:`.rls`) from
:math:`\hat\theta = 0` and a large diagonal covariance. The model is *stable* once
:math:`\|L(k)\hat e(k)\|_\infty < \epsilon` has held for ``stable_s`` seconds, and
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

__all__ = ["DEFAULT_PAIRS", "RlsArxZscore"]

DEFAULT_PAIRS = (
    {"name": "roll", "input": "roll_cmd", "output": "roll"},
    {"name": "roll_error", "input": "roll_cmd", "output": "roll_error"},
    {"name": "pitch", "input": "pitch_cmd", "output": "pitch"},
    {"name": "pitch_error", "input": "pitch_cmd", "output": "pitch_error"},
)

_REPEATED = ("hold", "fresh")


class _Pair:
    """State of one input/output pair, in the arrays :func:`~.kernels.rls_arx_advance`
    advances."""

    def __init__(self, det: RlsArxZscore, u_col: int, y_col: int):
        self.u_col, self.y_col = u_col, y_col
        nb = max(1, round(det.input_window_s * det.rate_hz))
        n = det.na + nb
        self.theta = np.zeros(n)                       # theta(0) = 0
        self.cov = np.eye(n) * det.p0                  # C(0) = p0 I
        self.ubuf = np.zeros(nb)
        self.ybuf = np.zeros(max(det.na, 1))
        self.phi, self.c_phi, self.gain = np.zeros(n), np.zeros(n), np.zeros(n)
        self.ints = np.zeros(kernels.ARX_INTS, dtype=np.int64)
        self.ints[[kernels.STREAK_FROM, kernels.VAR_FROM]] = -1
        self.floats = np.zeros(kernels.ARX_FLOATS)
        self.floats[kernels.LAST_VAR] = np.nan

    @property
    def updates(self) -> int:
        """RLS updates made."""
        return int(self.ints[kernels.UPDATES])

    @property
    def model_stable(self) -> bool:
        return bool(self.ints[kernels.MODEL_STABLE])

    @property
    def var_stable(self) -> bool:
        return bool(self.ints[kernels.VAR_STABLE])


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
        Initial RLS covariance :math:`C(0) = p_0 I`.
    warmup_samples : int
        Steps before a model may be declared stable.
    eps, stable_s : float
        Model stability: :math:`\\|L\\hat e\\|_\\infty < \\epsilon` for ``stable_s``.
    var_rtol, var_stable_s : float
        Variance stability.
    z_threshold : float
    repeated_samples : {"hold", "fresh"}

    Attributes
    ----------
    pairs_ : list
        Per-pair state: ``theta``, ``cov``, the regressor buffers, Welford's
        statistics, flags ``model_stable`` and ``var_stable``.
    last_ : dict of ndarray
        Per pair, the outputs of the last step (see :meth:`advance`).
    """

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
        self.stable_steps_ = round(self.stable_s * self.rate_hz)
        self.var_steps_ = round(self.var_stable_s * self.rate_hz)
        self.last_ = {k: np.full((1, len(self.pairs)), np.nan) for k in _OUTPUTS}
        return self

    def advance(self, x: np.ndarray, fresh: np.ndarray) -> dict[str, np.ndarray]:
        """Consume the steps of ``x`` and ``fresh`` (shape (n, m)); return per step and
        pair (shape (n, pairs)) ``z``, ``prediction`` and ``residual`` of an RLS update,
        and ``judged``, the residual of a pair whose model was already stable."""
        x = np.asarray(x, dtype=float)
        n = x.shape[0]
        out = {k: np.empty((len(self.pairs_), n)) for k in _OUTPUTS}
        for j, p in enumerate(self.pairs_):
            kernels.rls_arx_advance(
                np.ascontiguousarray(x[:, p.u_col]), np.ascontiguousarray(x[:, p.y_col]),
                np.ascontiguousarray(fresh[:, p.y_col]), p.ints, p.floats, p.theta, p.cov,
                p.ubuf, p.ybuf, p.phi, p.c_phi, p.gain, self.na, self.warmup_samples,
                self.eps, self.stable_steps_, self.var_rtol, self.var_steps_,
                self.repeated_samples == "fresh", out["z"][j], out["prediction"][j],
                out["residual"][j], out["judged"][j])
        out = {k: v.T for k, v in out.items()}
        self.last_ = {k: v[-1:] for k, v in out.items()}
        return out

    def update(self, x: np.ndarray, fresh: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        z = self.advance(x[None, :], fresh[None, :])["z"][0]
        return z, z > self.z_threshold

    def run(self, s: Sampled, probes: bool = False) -> tuple[np.ndarray, np.ndarray, dict]:
        out = self.reset().advance(s.x, s.fresh)
        kept = ({name: out[kind][:, j] for name, (kind, j) in _probe_index(self.pairs).items()}
                if probes else {})
        return out["z"], out["z"] > self.z_threshold, kept


_OUTPUTS = ("z", "prediction", "residual", "judged")


def _probe_index(pairs) -> dict[str, tuple[str, int]]:
    return {f"{p['name']}/{kind}": (kind, j) for j, p in enumerate(pairs)
            for kind in ("prediction", "residual")}


def _probes(pairs, last: dict[str, np.ndarray]) -> dict[str, float]:
    return {name: float(last[kind][j]) for name, (kind, j) in _probe_index(pairs).items()}
