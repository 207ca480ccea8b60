"""The residual bank and its learned fusion on synthetic data with known laws.

Each default model's law is written into synthetic fault-free segments; the bank must
recover it, and a step in each physical channel must alarm that channel within the
designed delay (the window ``W``), and never before the step.
"""

import numpy as np
import pytest

from alfa_bench.data import Sampled
from alfa_bench.methods import make_detector, run_detector
from alfa_bench.methods.residual_bank import DEFAULT_MODELS, ResidualBank
from alfa_bench.methods.windows import step_means

RATE_HZ = 20.0

#: the known law of each default model: slope per regressor at lag 0, others zero
LAWS = {
    "thrust": [9.81, 0.8, -0.5, 0.3, 0.02],
    "side": [0.4, -0.2, 1.5],
    "pitch": [-1.2, 0.3, 0.5],
    "roll": [-2.0, 0.4],
    "yaw": [0.6, 0.1],
}
NOISE = {"thrust": 0.15, "side": 0.08, "pitch": 0.02, "roll": 0.03, "yaw": 0.02}


def _ar1(rng, n, scale, a=0.7):
    x = np.zeros(n)
    e = rng.normal(0, scale, n)
    for k in range(1, n):
        x[k] = a * x[k - 1] + e[k]
    return x


def world(rng, duration_s=90.0, step=None):
    """A fault-free segment in which every default model's law holds exactly (plus
    noise and a per-segment offset), the outputs fresh at 10 Hz; ``step`` = (model,
    size, t) adds a step to that model's output from t on."""
    bank = ResidualBank()
    names = bank.signals()
    n = int(duration_s * RATE_HZ)
    t = np.arange(n) / RATE_HZ
    v = {"roll_cmd": _ar1(rng, n, 15.0), "pitch_cmd": _ar1(rng, n, 3.0),
         "altitude_error": rng.uniform(-20, 20) + _ar1(rng, n, 1.0, a=0.95)}
    v["roll"] = v["roll_cmd"] + _ar1(rng, n, 10.0)
    v["pitch"] = v["pitch_cmd"] + _ar1(rng, n, 3.0)
    v["roll_error"], v["pitch_error"] = v["roll"] - v["roll_cmd"], v["pitch"] - v["pitch_cmd"]
    order = ["roll", "pitch", "thrust", "yaw", "side"]     # rates before what they drive
    for name in order:
        spec = next(m for m in DEFAULT_MODELS if m["name"] == name)
        z = bank._regressors(np.column_stack([v.get(s, np.zeros(n)) for s in names]), names)
        j = sum(len(m["regressors"]) for m in DEFAULT_MODELS[:DEFAULT_MODELS.index(spec)])
        y = z[:, j:j + len(spec["regressors"])] @ np.array(LAWS[name])
        y += rng.uniform(-1, 1) + rng.normal(0, NOISE[name], n)
        if step is not None and step[0] == name:
            y += step[1] * (t >= step[2])
        v[spec["output"]] = y
    x = np.column_stack([v[s] for s in names])
    fresh = np.ones_like(x, dtype=bool)
    outputs = [names.index(m["output"]) for m in DEFAULT_MODELS]
    fresh[1::2, outputs] = False          # the IMU's 10 Hz on the 20 Hz grid
    for j in outputs:                     # a held value between fresh ones
        x[1::2, j] = x[0:-1:2, j][: x[1::2, j].size]
    return Sampled(t=t, x=x, fresh=fresh, names=names)


@pytest.fixture(scope="module")
def training():
    rng = np.random.default_rng(7)
    return [world(rng) for _ in range(12)]


@pytest.fixture(scope="module")
def bank(training):
    """Fitted with a small family-wise budget, so that the steps below are the only
    alarms by design."""
    return ResidualBank(false_alarm=0.01).fit(training)


@pytest.mark.parametrize("name", list(LAWS))
def test_each_model_recovers_its_known_law(bank, name):
    k = len(LAWS[name])
    theta = bank.theta_[name]
    np.testing.assert_allclose(theta[1:1 + k], LAWS[name], rtol=0.1, atol=0.05)
    np.testing.assert_allclose(theta[1 + k:], 0.0, atol=0.1 * max(map(abs, LAWS[name])))


@pytest.mark.parametrize("name", list(LAWS))
def test_a_step_is_found_within_the_window(bank, name):
    """A step of three thresholds' worth of fault-free steps is seen by its own channel
    within W of its start (half the window full is enough), never before."""
    c = bank.channels().index(name)
    size = -3.0 * bank.gamma_[name] * bank.sigma_[name]   # a drop: thrust is one-sided
    s = world(np.random.default_rng(100 + c), step=(name, size, 60.0))
    alarm = bank.alarms(bank.run(s)[0])
    first = s.t[np.argmax(alarm[:, c])] if alarm[:, c].any() else None
    assert first is not None and 60.0 <= first <= 60.0 + bank.window_s
    assert not alarm[s.t < 60.0].any()


def test_thrust_is_one_sided(bank):
    c = bank.channels().index("thrust")
    rise = 3.0 * bank.gamma_["thrust"] * bank.sigma_["thrust"]
    s = world(np.random.default_rng(3), step=("thrust", rise, 60.0))
    assert not bank.alarms(bank.run(s)[0])[:, c].any()


def test_false_alarms_per_flight_match_the_budget(training):
    """The threshold counts flights: fault-free segments like the training ones alarm
    at about the family-wise rate alpha (0.3 here), not per sample."""
    bank = ResidualBank(false_alarm=0.3).fit(training)
    rng = np.random.default_rng(11)
    alarmed = [bank.alarms(bank.run(world(rng))[0]).any() for _ in range(40)]
    assert 0.1 <= np.mean(alarmed) <= 0.55


def test_residuals_only_at_fresh_outputs(bank):
    s = world(np.random.default_rng(5))
    _, res = bank.residuals(s)
    outputs = [s.names.index(m["output"]) for m in DEFAULT_MODELS]
    assert not np.isfinite(res[~s.fresh[:, outputs]]).any()
    assert np.isfinite(res[s.fresh[:, outputs] & (s.t >= max(bank.lags_s))[:, None]]).all()


def test_step_means_ignores_stale_rows():
    v = np.r_[np.zeros(15), np.ones(5)][:, None]
    have = np.arange(20) % 2 == 0
    v[~have] = 99.0                        # a stale row's value must never count
    d = step_means(v, have, nw=4, nb=10)
    assert d[-1, 0] == 1.0 and np.isnan(d[:14]).all()


def test_too_few_segments_are_refused(training):
    with pytest.raises(ValueError, match="at least 3"):
        ResidualBank().fit(training[:2])


def test_learned_fusion_sees_a_step(training):
    fusion = make_detector("learned_fusion", {"false_alarm": 0.1}).fit(training)
    bank = fusion.bank_
    size = -4.0 * bank.sigma_["side"] * 3.0
    s = world(np.random.default_rng(21), step=("side", size, 60.0))
    alarm = fusion.alarms(fusion.run(s)[0])
    first = s.t[np.argmax(alarm[:, 0])] if alarm.any() else None
    assert first is not None and 60.0 <= first <= 60.0 + fusion.window_s


def test_run_on_a_flight_records_the_fresh_grid(corpus):
    """On the synthetic ALFA corpus, the bank reads the IMU's specific force."""
    from alfa_bench.data import load_flight
    from alfa_bench.methods import fault_free_segments
    flights = [load_flight(p) for p in sorted(corpus.iterdir())]
    det = ResidualBank()
    det.fit(fault_free_segments(det, flights, margin_s=1.0))
    trace = run_detector(det, next(f for f in flights if "engine_failure" in f.id
                                   and not f.emergency_trajectory))
    assert trace.channels == det.channels() and np.isfinite(trace.score).any()
