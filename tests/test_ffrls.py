"""Forgetting-factor RLS: tracking time constant, covariance wind-up guard, joint test."""

import numpy as np
import pytest

from alfa_bench.methods.ffrls_monitor import joint_thresholds
from alfa_bench.methods.rls import RecursiveLeastSquares


@pytest.mark.parametrize("lam", [0.95, 0.98])
def test_a_parameter_step_is_tracked_with_time_constant_one_over_one_minus_lambda(lam):
    rng = np.random.default_rng(0)
    rls = RecursiveLeastSquares(1, p0=1.0, forgetting=lam).reset()
    for _ in range(2000):                       # settle on a = 1
        phi = rng.normal(size=1)
        rls.update(phi, 1.0 * phi[0])
    tau = round(1 / (1 - lam))
    errors = []
    for _ in range(3 * tau):                    # a steps to 2, noise-free
        phi = rng.normal(size=1)
        rls.update(phi, 2.0 * phi[0])
        errors.append(2.0 - rls.theta_[0])
    # with E[phi^2] = 1 the error decays like lam^k: e^-1 left after tau samples
    assert errors[tau - 1] == pytest.approx(np.exp(-1), abs=0.12)
    assert errors[3 * tau - 1] < 0.1


def test_covariance_winds_up_without_excitation_and_the_guard_bounds_it():
    lam, steps = 0.95, 300
    phi = np.array([0.0, 1.0])                  # the first parameter is never excited
    free = RecursiveLeastSquares(2, p0=1.0, forgetting=lam).reset()
    guarded = RecursiveLeastSquares(2, p0=1.0, forgetting=lam, max_trace=10.0).reset()
    for _ in range(steps):
        free.update(phi, 1.0)
        guarded.update(phi, 1.0)
    assert free.P_[0, 0] == pytest.approx(lam ** -steps, rel=1e-6)
    assert np.trace(guarded.P_) <= 10.0 + 1e-9
    assert np.all(np.linalg.eigvalsh(guarded.P_) > 0)
    # the guarded estimator still learns what is excited
    assert guarded.theta_[1] == pytest.approx(1.0, abs=1e-3)


def test_joint_thresholds_meet_the_false_alarm_probability():
    rng = np.random.default_rng(1)
    g, t = rng.exponential(size=(2, 200_000))
    pf = 1e-3
    tg, tt = joint_thresholds(g, t, pf)
    assert np.mean((g > tg) & (t > tt)) <= pf
    # independent tests: each marginal level is about sqrt(P_F), far below the single test's
    assert np.mean(g > tg) == pytest.approx(np.sqrt(pf), rel=0.3)
    # fully dependent tests gain nothing from combining
    tg, tt = joint_thresholds(g, g, pf)
    assert np.mean(g > tg) <= pf
