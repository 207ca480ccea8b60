"""Resampled calibration pools (analysis/stability.py): the bootstrap thresholds equal
scipy's fit of each pool, a detection far above its threshold survives every pool and
one at its edge does not, and no pool holds a flight of the date it scores."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import alfa_bench as ab
from alfa_bench.analysis import detections
from alfa_bench.analysis.held_out import HeldOutError
from alfa_bench.analysis.stability import (
    calibration_table,
    pool_draws,
    pool_first_alarms,
    stability_table,
    survival,
)
from alfa_bench.methods import Detector, MaximaThresholds, Trace
from alfa_bench.methods.extremes import gumbel_threshold, gumbel_thresholds

REPO = Path(__file__).resolve().parent.parent


def test_pool_thresholds_are_scipys_fit_of_each_pool():
    rng = np.random.default_rng(3)
    maxima = rng.gumbel(2.0, 0.5, 25)
    maxima[4] = 30.0                                   # one absurd flight: capped
    counts = rng.multinomial(25, np.full(25, 1 / 25), size=12)
    pooled = gumbel_thresholds(maxima, counts, 0.95)
    for row, got in zip(counts, pooled, strict=True):
        assert got == pytest.approx(gumbel_threshold(np.repeat(maxima, row), 0.95),
                                    rel=1e-10)


def test_pools_are_bootstraps_drawn_the_same_for_every_run():
    flights = [f"f{i}" for i in range(20)]
    a, b = pool_draws(flights, 50, 0, "2018-07-18"), pool_draws(flights, 50, 0, "2018-07-18")
    assert a == b and a != pool_draws(flights, 50, 0, "2018-09-11")
    assert all(sum(d.values()) == 20 and set(d) <= set(flights) for d in a)


class Level(MaximaThresholds, Detector):
    """A stand-in whose per-flight maxima are set by hand."""

    def __init__(self, false_alarm=0.1):
        self.false_alarm = false_alarm

    def signals(self):
        return ("roll",)

    def update(self, x, fresh):
        return x[:1]


def _fitted(maxima: np.ndarray) -> Level:
    d = Level()
    d.maxima_ = {"level": list(maxima)}
    d.maxima_flights_ = {"level": [f"f{i}" for i in range(len(maxima))]}
    return d.rethreshold()


def _record(trace: Trace, onset_s: float, pools: np.ndarray) -> dict:
    first = trace.first_alarm_s()
    return {"onset_s": onset_s, "first_alarm_s": first,
            "stability": {"pools": len(pools),
                          "first_alarm_s": pool_first_alarms(trace, pools)}}


def _trace(d: Detector, peak: float) -> Trace:
    t = np.arange(0.0, 60.0, 0.05)
    score = np.where(t >= 30.0, peak, 0.2 * d.thresholds()[0])[:, None]
    return Trace(t=t, score=score, alarm=d.alarms(score), channels=("level",),
                 threshold=d.thresholds())


def test_far_above_survives_every_pool_and_the_edge_does_not():
    d = _fitted(np.random.default_rng(5).gumbel(1.0, 0.3, 30))
    pools = d.pool_thresholds(pool_draws([f"f{i}" for i in range(30)], 200, 0, "day"))
    gamma = d.thresholds()[0]
    assert np.nanstd(pools) > 0
    far = _record(_trace(d, 3.0 * gamma), 30.0, pools)
    edge = _record(_trace(d, 1.01 * gamma), 30.0, pools)
    assert far["first_alarm_s"] == edge["first_alarm_s"] == 30.0      # both detected
    assert survival(far, 5.0) == 1.0
    assert survival(edge, 5.0) < 0.7
    # a pool's threshold the score never reaches is a miss under that pool
    assert None in edge["stability"]["first_alarm_s"]


@pytest.fixture(scope="module")
def local(corpus, tmp_path_factory):
    return ab.load_corpus(corpus.parent, config=ab.load_config(REPO / "config/config.yaml"),
                          cache=tmp_path_factory.mktemp("cache"))


def test_every_calibrated_record_holds_its_pools_and_the_tables_count_them(local):
    result = ab.evaluate("residual_bank", local)
    pools = local.config["stability"]["pools"]
    assert {r["stability"]["pools"] for r in result.records} == {pools}
    assert result.per_flight["survival"].between(0, 1).all()
    table = stability_table(result.records, local.manifest, ["all"], 5.0)
    row = table.iloc[0]
    assert row["pools"] == pools and row["stable_detections"] <= row["detections"]
    assert row["detections_low"] <= row["detections_mean"] <= row["detections_high"]
    assert {"stable_detections", "rank_range"} <= set(result.summary.columns)
    folds = calibration_table(result.records)
    assert (folds["fault_free_hours"] > 0).all() and (folds["smallest_level"] < 1).all()
    # an uncalibrated run has no pools, and says so
    plain = ab.evaluate("rls_arx_zscore", local)
    assert all(r["stability"] is None for r in plain.records)
    assert plain.per_flight["survival"].isna().all()


def test_no_pool_holds_a_flight_of_the_date_it_scores(local, monkeypatch):
    def leaky(flights, pools, seed, fold):
        # a pool of the scored date's flights: the check must stop the run
        scored = local.manifest.loc[local.manifest["date"].astype(str) == fold, "flight"]
        return [{str(scored.iloc[0]): len(flights)}]

    honest = pool_draws
    checked = []

    def spy(flights, pools, seed, fold):
        draws = honest(flights, pools, seed, fold)
        dates = pd.Series([f.split("_")[1][:10] for d in draws for f in d])
        checked.append((fold, set(dates)))
        return draws

    monkeypatch.setattr(detections, "pool_draws", spy)
    ab.evaluate("coincidence", local)
    assert checked and all(fold not in dates for fold, dates in checked)
    monkeypatch.setattr(detections, "pool_draws", leaky)
    with pytest.raises(HeldOutError, match="calibration would see"):
        ab.evaluate("coincidence", local)


def test_a_refit_on_the_same_pools_sits_beside_the_thresholds_alone(local):
    from alfa_bench.analysis.stability import refit_first_alarms, refit_table

    config = local.config
    result = ab.evaluate("residual_bank", local)
    spec = config["methods"]["residual_bank"]
    firsts = refit_first_alarms(spec, local.flights, local.manifest, config["calibration"],
                                config["stability"], refits=3)
    assert set(firsts) == {r["flight"] for r in result.records}
    assert {len(v) for v in firsts.values()} == {3}
    table = refit_table(result.records, {"residual_bank": firsts}, local.manifest,
                        ["all"], 5.0)
    row = table.iloc[0]
    assert row["pools"] == 3 and 0 <= row["outcomes_agree"] <= 1
    assert row["thresholds_min"] <= row["thresholds_mean"] <= row["thresholds_max"]
