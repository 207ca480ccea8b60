"""The detectability ceiling: its AUC, the features' causality, and a synthetic
energy loss found where it is written."""

import numpy as np
import pandas as pd
import pytest

from alfa_bench.analysis.ceiling import auc_interval, ceiling_markdown, ceiling_table
from alfa_bench.data import load_flight
from alfa_bench.data.synthetic import write_flight
from alfa_bench.methods.physics import FEATURES, WARMUP_S, features


def test_auc_counts_pairs_and_ties():
    assert auc_interval(np.array([3.0, 4.0]), np.array([1.0, 2.0]))[0] == 1.0
    assert auc_interval(np.array([1.0, 2.0]), np.array([3.0, 4.0]))[0] == 0.0
    auc, lo, hi = auc_interval(np.array([1.0, 2.0, 3.0]), np.array([1.0, 2.0, 3.0]))
    assert auc == 0.5 and lo < 0.5 < hi


def _plain_auc_interval(fault, free, seed=0, n_boot=2000):
    """The bootstrap as first written: every resample drawn and compared pair by pair."""
    def auc(a, b):
        d = a[:, None] - b[None, :]
        return float(np.mean((d > 0) + 0.5 * (d == 0)))

    rng = np.random.default_rng(seed)
    boots = [auc(rng.choice(fault, fault.size), rng.choice(free, free.size))
             for _ in range(n_boot)]
    lo, hi = np.quantile(boots, [0.025, 0.975])
    return auc(fault, free), float(lo), float(hi)


@pytest.mark.parametrize("sizes", [(1, 5), (2, 2), (7, 30), (23, 47)])
@pytest.mark.parametrize("decimals", [None, 0])
def test_the_resample_counts_give_the_plain_bootstrap_to_the_bit(sizes, decimals):
    rng = np.random.default_rng(sum(sizes))
    fault, free = rng.normal(0.5, 1.0, sizes[0]), rng.normal(0.0, 1.0, sizes[1])
    if decimals is not None:          # ties between and within the sets
        fault, free = fault.round(decimals), free.round(decimals)
    assert auc_interval(fault, free) == _plain_auc_interval(fault, free)
    assert auc_interval(fault, free, seed=3, n_boot=50) == _plain_auc_interval(
        fault, free, seed=3, n_boot=50)


@pytest.fixture(scope="module")
def flights(corpus):
    return {p.name: load_flight(p) for p in sorted(corpus.iterdir())}


def test_a_synthetic_energy_loss_passes_every_fault_free_maximum(flights):
    """The corpus's engine flights lose 2 m/s of climb and 0.5 m/s^2 of speed at onset:
    the energy features see it within the 5 s deadline, above every fault-free segment,
    and a feature of another class does not."""
    table = ceiling_table(flights, {"all": list(flights)}, deadline_s=5.0, margin_s=1.0)
    engine = table[table["fault_class"] == "engine"].set_index("feature")
    for feature in ("energy_rate_drop", "climb_rate_drop"):
        assert engine.loc[feature, "auc"] == 1.0
        assert engine.loc[feature, "above_free_max"] == engine.loc[feature, "fault_flights"] == 2
    assert engine.loc["roll_asymmetry", "above_free_max"] < 2
    rudder = table[table["fault_class"] == "rudder"].set_index("feature")
    assert rudder.loc["accel_y_shift", "above_free_max"] == 1
    assert set(table["feature"]) == set(FEATURES)
    assert table.groupby(["subset", "fault_class"])["best"].any().all()
    text = ceiling_markdown(table, 5.0)
    assert "all: the best single feature per class" in text and "`energy_rate_drop`" in text


def test_features_are_causal_and_wait_for_their_baseline(tmp_path):
    """Changing the energy after onset changes no feature before it."""
    a = load_flight(write_flight(tmp_path / "a", "carbonZ_2018-07-18-15-53-31_1_engine_failure",
                                 onset_s=50.0))
    b = load_flight(write_flight(tmp_path / "b", "carbonZ_2018-07-18-15-53-31_1_engine_failure",
                                 onset_s=60.0))
    ta, fa = features(a)
    tb, fb = features(b)
    before = ta < 50.0
    np.testing.assert_array_equal(ta, tb)
    for name in FEATURES:
        np.testing.assert_array_equal(fa[name][before], fb[name][before], err_msg=name)
        assert np.isnan(fa[name][ta < WARMUP_S]).all()
    assert not np.array_equal(fa["climb_rate_drop"], fb["climb_rate_drop"], equal_nan=True)


def test_a_flight_without_the_energy_topics_is_left_out(tmp_path, flights):
    folder = write_flight(tmp_path / "p", "carbonZ_2018-07-18-15-53-31_2_engine_failure",
                          onset_s=50.0)
    next(folder.glob("*rel_alt.csv")).unlink()
    mixed = {**flights, folder.name: load_flight(folder)}
    table = ceiling_table(mixed, {"all": list(mixed)}, 5.0, 1.0)
    assert isinstance(table, pd.DataFrame)
    engine = table[(table["fault_class"] == "engine") & (table["feature"] == "accel_x_drop")]
    assert int(engine["fault_flights"].iloc[0]) == 2
