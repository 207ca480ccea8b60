"""The RLS-ARX z-score detector on a synthetic ARX system with a known change."""

import numpy as np
import pytest

from alfa_bench.data.synthetic import arx_response, command
from alfa_bench.methods import make_detector

RATE = 25.0
PAIR = ({"name": "roll", "input": "roll_cmd", "output": "roll"},)


def stream(n=3000, onset=None, seed=0):
    rng = np.random.default_rng(seed)
    u = command(n, RATE, rng)
    y = arx_response(u, 0.8, 0.2, rng.normal(0, 0.05, n))
    if onset is not None:
        y[onset:] = arx_response(u, 0.8, 0.0, rng.normal(0, 0.05, n))[onset:] + 5.0
    return u, y


def drive(det, u, y, fresh=None):
    det.reset()
    fresh = np.ones_like(u, dtype=bool) if fresh is None else fresh
    score = np.array([det.update(np.array([uu, yy]), np.array([True, f]))[0]
                      for uu, yy, f in zip(u, y, fresh, strict=True)])
    return score, det.alarms(score[:, None])[:, 0]


def test_identifies_the_system_and_arms():
    det = make_detector("rls_arx_zscore", {"pairs": PAIR})
    u, y = stream()
    score, alarm = drive(det, u, y)
    p = det.pairs_[0]
    assert p.model_stable and p.var_stable
    # theta = [a1, b0, b1, ...]: the true system is a1 = 0.8, b0 = 0.2, the rest 0
    np.testing.assert_allclose(p.theta[:2], [0.8, 0.2], atol=0.02)
    np.testing.assert_allclose(p.theta[2:], 0, atol=0.02)
    armed = np.flatnonzero(np.isfinite(score))[0]
    assert armed >= det.warmup_samples
    assert not alarm.any(), "fault-free Gaussian data must not alarm at z > 4.5"


def test_alarms_soon_after_a_change_and_not_before():
    onset = 2000
    det = make_detector("rls_arx_zscore", {"pairs": PAIR})
    u, y = stream(onset=onset)
    _, alarm = drive(det, u, y)
    assert not alarm[:onset].any()
    first = np.flatnonzero(alarm)[0]
    assert onset <= first < onset + RATE  # within one second


def test_fresh_mode_updates_only_on_new_measurements():
    det = make_detector("rls_arx_zscore", {"pairs": PAIR, "repeated_samples": "fresh"})
    u, y = stream()
    fresh = np.zeros(u.size, dtype=bool)
    fresh[::2] = True
    drive(det, u, y, fresh)
    assert det.pairs_[0].updates <= fresh.sum()


def test_bad_parameters_are_refused():
    with pytest.raises(TypeError, match="must be a number"):
        make_detector("rls_arx_zscore", {"p0": "1.0e6"})
    with pytest.raises(TypeError, match="no parameter 'zz'"):
        make_detector("rls_arx_zscore", {"zz": 1})
    with pytest.raises(ValueError, match="repeated_samples"):
        make_detector("rls_arx_zscore", {"repeated_samples": "skip"}).reset()
