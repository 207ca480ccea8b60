"""The windowed GLRT, its thresholds, and the GLRT-on-residuals detector."""

import numpy as np
import pytest
from scipy import stats

from alfa_bench.data import Sampled
from alfa_bench.methods.glrt import (
    WindowedGlrt,
    chi2_threshold,
    empirical_threshold,
    glrt_statistic,
)
from alfa_bench.methods.glrt_residuals import GlrtResiduals


def run(x, window, sigma2=1.0):
    glrt = WindowedGlrt(window, sigma2).reset()
    return np.array([glrt.update(v) for v in x]), glrt


def test_statistic_is_the_maximised_log_likelihood_ratio():
    x = np.random.default_rng(0).normal(size=30)
    g, _ = run(x, window=8, sigma2=2.0)
    for k in range(x.size):
        brute = max(x[j:k + 1].sum() ** 2 / (2 * 2.0 * (k + 1 - j))
                    for j in range(max(0, k - 7), k + 1))
        assert g[k] == pytest.approx(brute, rel=1e-12)


def test_batch_statistic_equals_the_streamed_one():
    x = np.random.default_rng(5).normal(1.0, 2.0, size=500)
    np.testing.assert_allclose(glrt_statistic(x, 40, 3.0), run(x, 40, 3.0)[0], rtol=1e-9)


def test_mean_jump_is_found_within_the_window_with_its_instant_and_size():
    rng = np.random.default_rng(1)
    window, onset, jump = 50, 400, 1.5
    x = rng.normal(size=800)
    x[onset:] += jump
    gamma = empirical_threshold(glrt_statistic(rng.normal(size=200_000), window, 1.0), 5e-4)
    g, glrt = run(x[:onset + window], window)
    assert not (g[:onset] > gamma).any()
    first = int(np.argmax(g > gamma))
    assert onset <= first < onset + window
    assert glrt.change_ == pytest.approx(window - 1, abs=10)   # change instant ~ onset
    assert glrt.mean_ == pytest.approx(jump, abs=0.5)


def test_chi2_threshold_holds_for_one_change_instant_on_white_noise():
    gamma = chi2_threshold(0.01)
    assert gamma == pytest.approx(0.5 * stats.chi2.ppf(0.99, 1))
    g = glrt_statistic(np.random.default_rng(2).normal(size=100_000), 1, 1.0)
    assert np.mean(g > gamma) == pytest.approx(0.01, abs=0.002)


def test_chi2_threshold_is_exceeded_far_more_often_on_correlated_residuals():
    rng = np.random.default_rng(3)
    e = rng.normal(size=100_000)
    ar = np.empty_like(e)
    ar[0] = e[0]
    for k in range(1, e.size):
        ar[k] = 0.9 * ar[k - 1] + e[k]
    g = glrt_statistic(ar / ar.std(), 50, 1.0)
    assert np.mean(g > chi2_threshold(5e-4)) > 20 * 5e-4
    assert np.mean(g > empirical_threshold(g, 5e-4)) <= 5e-4


def test_empirical_threshold_refuses_too_few_samples():
    with pytest.raises(ValueError, match="cannot resolve"):
        empirical_threshold(np.ones(100), 5e-4)


def arx_segment(n, rng, theta=(0.7, 0.3, 0.2), onset=None):
    u = rng.normal(size=n)
    y = np.zeros(n)
    for k in range(1, n):
        b = theta[1:] if onset is None or k < onset else (0.0, 0.0)
        y[k] = theta[0] * y[k - 1] + b[0] * u[k] + b[1] * u[k - 1] + rng.normal(0, 0.1)
    x = np.c_[u, y]
    return Sampled(t=np.arange(n) / 10.0, x=x, fresh=np.ones_like(x, dtype=bool),
                   names=("roll_cmd", "roll"))


def test_glrt_residuals_identifies_the_arx_model_and_finds_the_change():
    rng = np.random.default_rng(4)
    det = GlrtResiduals(pairs=[{"name": "roll", "input": "roll_cmd", "output": "roll"}],
                        rate_hz=10.0, input_window_s=0.2, window_s=2.0)
    det.fit([arx_segment(3000, rng) for _ in range(4)])
    np.testing.assert_allclose(det.theta_[0], [0.7, 0.3, 0.2], atol=0.02)
    assert det.var_[0] == pytest.approx(0.01, rel=0.1)
    s = arx_segment(1000, rng, onset=600)
    streamed = GlrtResiduals(**det.get_params())
    streamed.theta_ = det.theta_
    streamed._reset_residuals()
    r = [streamed._residual_step(x, f) for x, f in zip(s.x, s.fresh, strict=True)]
    np.testing.assert_allclose(np.array(r), det._residual_run(s), rtol=1e-9)
    det.reset()
    alarms = np.array([det.alarms(det.update(x, f))[0] for x, f in zip(s.x, s.fresh, strict=True)])
    assert alarms[600:640].any()
