"""Numerical safety: covariances stay symmetric positive definite and bounded, and
every detector keeps its scores finite (or NaN while not armed) through pathological
inputs, raises no floating-point error, and recovers on normal data."""

import numpy as np
import pytest

from alfa_bench.data import Sampled, load_flight, sample
from alfa_bench.methods import REGISTRY, fault_free_segments, make_detector, training_segments
from alfa_bench.methods.rls import RecursiveLeastSquares


def assert_spd(cov):
    np.testing.assert_array_equal(cov, cov.T)
    assert np.linalg.eigvalsh(cov).min() > 0


@pytest.mark.parametrize("lam, max_trace", [(1.0, np.inf), (0.98, 50.0), (0.9, 5.0)])
def test_rls_covariance_stays_spd_and_bounded_without_excitation(lam, max_trace):
    """A constant regressor excites one direction only, for 50 000 steps."""
    rls = RecursiveLeastSquares(4, p0=10.0, forgetting=lam, max_trace=max_trace).reset()
    bound = min(max_trace, 40.0) if lam == 1.0 else max_trace
    phi = np.array([1.0, 0.5, 0.0, 1.0])
    for k in range(50_000):
        rls.update(phi, 2.0)
        if k % 5000 == 0:
            assert_spd(rls.P_)
            assert np.trace(rls.P_) <= bound * (1 + 1e-12)
    assert_spd(rls.P_)
    # the bounded trace also shrinks the excited direction, which slows the last digits
    assert rls.theta_ @ phi == pytest.approx(2.0, rel=1e-4)


def test_rls_arx_covariances_stay_spd_over_a_long_flight(corpus):
    longest = max((load_flight(p) for p in corpus.iterdir()), key=lambda f: f.duration_s)
    det = make_detector("rls_arx_zscore")
    det.run(sample(longest, det.signals(), det.rate_hz))
    for pair in det.pairs_:
        assert_spd(pair.P)
        assert np.trace(pair.P) <= det.p0 * pair.P.shape[0]


def test_the_okid_filters_are_stable_observers(corpus):
    """The steady-state filter's error dynamics A - A K C have spectral radius < 1, so
    innovations cannot grow without bound."""
    flights = [load_flight(p) for p in sorted(corpus.iterdir())]
    det = make_detector("kalman_okid").fit(fault_free_segments(
        make_detector("kalman_okid"), flights, margin_s=1.0))
    for m in det.models_:
        assert np.abs(np.linalg.eigvals(m.A - m.L @ m.C)).max() < 1.0


def pathological(x: np.ndarray, case: str) -> np.ndarray:
    n = x.shape[0]
    out = {"constant": lambda: np.tile(x[n // 2], (n, 1)),
           "step": lambda: np.where(np.arange(n)[:, None] < n // 4, x[0], x[0] + 10.0),
           "ramp": lambda: x[0] + np.linspace(0.0, 50.0, n)[:, None],
           "huge": lambda: x * 1e6,
           "tiny": lambda: x * 1e-9,
           "spike": lambda: np.where(np.arange(n)[:, None] == n // 3, x * 1e9, x)}[case]()
    return np.vstack([out[: n // 2], x[n // 2:]])   # pathological, then normal again


@pytest.fixture(scope="module")
def fitted(corpus):
    flights = [load_flight(p) for p in sorted(corpus.iterdir())]
    scored = next(f for f in flights if f.fault and f.fault.onset_s)
    out = {}
    for name in REGISTRY:
        det = make_detector(name)
        if det.calibrated:
            det.fit(training_segments(det, flights, margin_s=1.0))
        out[name] = (det, sample(scored, det.signals(), det.rate_hz))
    return out


@pytest.mark.parametrize("case", ["constant", "step", "ramp", "huge", "tiny", "spike"])
@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_detectors_survive_pathological_inputs_and_recover(fitted, name, case):
    det, s = fitted[name]
    x = pathological(s.x, case)
    bad = Sampled(t=s.t, x=x, fresh=np.ones_like(x, dtype=bool), names=s.names)
    with np.errstate(all="raise"):
        score, _ = det.run(bad)
    assert not np.isneginf(score).any()
    if name != "rls_arx_zscore":  # its z is +inf, by design, when the error variance is 0
        assert not np.isinf(score).any()
    tail = score[-s.t.size // 4:]
    assert np.isfinite(tail).all(), "a channel did not recover on normal data"
