"""The compiled core against the plain per-sample NumPy implementation it replaced.

The compiled kernels sum their dot products in another order, so results agree to
rounding; RLS with C(0) = 1e6 I amplifies rounding early on, hence the stated
tolerance on the z-score: 1e-4 relative (measured: 1.4e-5 over the 39 local flights,
with identical alarms on every one).
"""

import numpy as np
import pytest
from reference_rls_arx import PlainRecursiveLeastSquares, PlainRlsArxZscore

from alfa_bench.data import load_flight
from alfa_bench.methods import make_detector, run_detector
from alfa_bench.methods.glrt import WindowedGlrt
from alfa_bench.methods.kernels import glrt_advance
from alfa_bench.methods.rls import RecursiveLeastSquares

Z_RTOL = 1e-4


def assert_same_detection(fast, plain):
    np.testing.assert_array_equal(fast.alarm, plain.alarm)
    np.testing.assert_array_equal(np.isfinite(fast.score), np.isfinite(plain.score))
    ok = np.isfinite(plain.score)
    err = np.abs(fast.score[ok] - plain.score[ok]) / np.maximum(1.0, np.abs(plain.score[ok]))
    assert err.max(initial=0.0) < Z_RTOL
    for name, values in plain.probes.items():
        np.testing.assert_array_equal(np.isnan(fast.probes[name]), np.isnan(values))


@pytest.mark.parametrize("lam, max_trace", [(1.0, np.inf), (0.95, 50.0)])
def test_rls_step_matches_the_plain_numpy_step(lam, max_trace):
    rng = np.random.default_rng(8)
    fast = RecursiveLeastSquares(5, 100.0, lam, max_trace).reset()
    plain = PlainRecursiveLeastSquares(5, 100.0, lam, max_trace).reset()
    for _ in range(2000):
        phi = rng.normal(size=5) * rng.choice([0.0, 1.0, 1e3])
        y = phi @ [1, -2, 0.5, 0, 3] + rng.normal()
        assert fast.update(phi, y) == pytest.approx(plain.update(phi, y), rel=1e-9, abs=1e-9)
    np.testing.assert_allclose(fast.theta_, plain.theta_, rtol=1e-9)
    np.testing.assert_allclose(fast.P_, plain.P_, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(fast.K_, plain.K_, rtol=1e-9, atol=1e-15)


def test_glrt_kernel_is_the_streaming_glrt_bit_for_bit():
    rng = np.random.default_rng(9)
    x = np.r_[rng.normal(size=300), rng.normal(2.0, 1.0, size=100)]
    x[[5, 50, 51]] = np.nan
    ref = WindowedGlrt(20, 1.3).reset()
    expected = np.array([ref.update(v) if np.isfinite(v) else np.nan for v in x])
    g = np.empty(x.size)
    glrt_advance(x, np.zeros(20), np.zeros(1, dtype=np.int64), 1.3, g)
    np.testing.assert_array_equal(g, expected)


@pytest.mark.parametrize("repeated", ["hold", "fresh"])
def test_compiled_rls_arx_detects_like_the_plain_one(corpus, repeated):
    for path in sorted(corpus.iterdir()):
        flight = load_flight(path)
        fast = run_detector(make_detector("rls_arx_zscore", {"repeated_samples": repeated}),
                            flight, probes=True)
        plain = run_detector(PlainRlsArxZscore(repeated_samples=repeated), flight, probes=True)
        assert_same_detection(fast, plain)


def test_compiled_rls_arx_detects_like_the_plain_one_on_real_flights(real_processed):
    engine = sorted(real_processed.glob("*engine_failure"))[:2]
    for path in [*engine, *sorted(real_processed.glob("*no_failure"))[:1]]:
        flight = load_flight(path)
        fast = run_detector(make_detector("rls_arx_zscore"), flight, probes=True)
        plain = run_detector(PlainRlsArxZscore(), flight, probes=True)
        assert_same_detection(fast, plain)
