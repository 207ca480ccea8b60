"""The public study's classifier: its residuals, features and threshold rule as the
study states them, and the positives and maxima of this project's protocol."""

import numpy as np
import pandas as pd
import pytest

from alfa_bench.data import Sampled
from alfa_bench.methods import CalibrationError, Labelled
from alfa_bench.methods.residual_logistic import (
    CHANNELS,
    INPUTS,
    ResidualLogistic,
    ResidualLogisticPublished,
    _trailing,
    best_accuracy_threshold,
)

RATE = 10.0


def _flight(name, seed, onset_s=None, emr=False, n=900):
    """A flight whose channels follow (1) with known coefficients, and after onset a
    forward acceleration 2 m/s^2 short of them (an engine lost)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / RATE
    roll, roll_cmd = rng.normal(0, 15, n), rng.normal(0, 15, n)
    pitch, pitch_cmd = rng.normal(2, 3, n), rng.normal(2, 3, n)
    alt_err, aspd_err = rng.normal(0, 5, n), rng.normal(0, 150, n)        # m, cm/s
    vel = rng.normal(0, 1, (n, 3)) + [14.0, 5.0, 0.0]
    speed = np.linalg.norm(vel, axis=1)
    noise = rng.normal(0, 0.1, (n, 5))
    ax = 0.5 + 0.05 * alt_err + 0.3 * aspd_err / 100 + 0.17 * pitch + noise[:, 0]
    ay = 0.2 + noise[:, 1]
    p = 0.01 * (roll_cmd - roll) + noise[:, 2]
    q = 0.02 * (pitch_cmd - pitch) + 1e-4 * roll ** 2 + noise[:, 3]
    r = 0.9 * 9.80665 * np.tan(np.radians(roll)) / np.maximum(speed, 5.0) + noise[:, 4]
    if onset_s is not None:
        ax = ax - 2.0 * (t >= onset_s)
    columns = {"accel_x": ax, "accel_y": ay, "roll_rate": p, "pitch_rate": q, "yaw_rate": r,
               "roll": roll, "roll_cmd": roll_cmd, "pitch": pitch, "pitch_cmd": pitch_cmd,
               "altitude_error": alt_err, "airspeed_error": aspd_err,
               "nav_vel_north": vel[:, 0], "nav_vel_east": vel[:, 1], "nav_vel_down": vel[:, 2]}
    x = np.column_stack([columns[c] for c in INPUTS])
    s = Sampled(t, x, np.ones_like(x, bool), INPUTS, name)
    return Labelled(s, onset_s, "none" if onset_s is None else "engine", emr)


def _corpus():
    return [_flight("carbonZ_2018-07-18-15-53-31_1_engine_failure", 0, 60.0),
            _flight("carbonZ_2018-07-18-16-37-39_1_no_failure", 1),
            _flight("carbonZ_2018-07-30-16-39-00_1_engine_failure", 2, 70.0),
            _flight("carbonZ_2018-07-30-16-39-00_3_no_failure", 3),
            _flight("carbonZ_2018-09-11-14-16-55_no_failure", 4),
            _flight("carbonZ_2018-09-11-11-56-30_engine_failure", 5, 55.0),
            _flight("carbonZ_2018-10-05-15-55-10_engine_failure_with_emr_traj", 6, 50.0,
                    emr=True),
            _flight("carbonZ_2018-10-05-14-34-20_1_no_failure", 7)]


def test_the_residual_models_recover_the_physics_they_are_fitted_on():
    d = ResidualLogistic().fit_model(_corpus())
    np.testing.assert_allclose(d.weights_["accel_x"], [0.5, 0.05, 0.3, 0.17], atol=0.02)
    np.testing.assert_allclose(d.weights_["yaw_rate"], [0.0, 0.9], atol=0.02)
    np.testing.assert_allclose(d.weights_["pitch_rate"], [0.0, 0.02, 1e-4], atol=2e-3)
    # each residual is scaled by its nominal spread, the noise's 0.1
    assert all(0.09 < d.sigma_[c] < 0.11 for c in CHANNELS)


def test_the_windows_are_the_studys_pandas_rolling_ones():
    z = np.random.default_rng(0).normal(size=(40, 5))
    for w in (10, 30):
        mean, std = _trailing(z, w)
        frame = pd.DataFrame(z)
        np.testing.assert_allclose(mean, frame.rolling(w, min_periods=1).mean(), atol=1e-12)
        np.testing.assert_allclose(std, frame.rolling(w, min_periods=2).std().fillna(0.0),
                                   atol=1e-12)


def test_the_fault_scores_high_and_the_warm_up_not_at_all():
    d = ResidualLogisticPublished().fit(_corpus())
    test = _flight("carbonZ_2018-10-18-11-08-24_engine_failure", 9, 60.0)
    score = d.run(test.sampled)[0][:, 0]
    assert np.isnan(score[:150]).all() and np.isfinite(score[150:]).all()
    assert d.alarms(score[:, None])[620:, 0].all()          # from 2 s after onset on
    assert not d.alarms(score[:, None])[:600, 0].any()


def test_the_published_threshold_is_the_middle_of_the_first_interval_of_best_accuracy():
    before = np.array([1.0, 2.0, 5.0, -np.inf])
    after = np.array([4.0, 3.0, 6.0, -np.inf])
    faulty = np.array([True, True, True, False])
    # h in [2, 3): flights 1 and 2 detected, 3 early, 4 quiet: 3 of 4, the best
    assert best_accuracy_threshold(before, after, faulty) == 2.5
    # best from the last candidate on: one above it
    assert best_accuracy_threshold(np.array([1.0]), np.array([-np.inf]),
                                   np.array([False])) == 1.5
    with pytest.raises(CalibrationError):
        best_accuracy_threshold(np.array([-np.inf]), np.array([-np.inf]), np.array([False]))


def test_the_published_rule_reports_its_training_accuracy():
    d = ResidualLogisticPublished().fit(_corpus())
    assert d.fitted()["training_accuracy"] == 1.0
    assert d.thresholds()[0] > 0


def test_emergency_trajectory_faults_are_positives_only_when_asked():
    emr_only = [f if f.onset_s is None or f.emergency_trajectory else
                Labelled(f.sampled, None, "none") for f in _corpus()]
    ResidualLogistic(positives="all").fit_model(emr_only)
    with pytest.raises(CalibrationError, match="no faulty steps"):
        ResidualLogistic(positives="no_emr").fit_model(emr_only)
    for cls in (ResidualLogistic, ResidualLogisticPublished):
        with pytest.raises(ValueError, match="positives"):
            cls(positives="some").fit(_corpus())


def test_each_maximum_comes_from_a_model_that_never_saw_its_date(monkeypatch):
    """The fault-free maxima are out of sample: the model scoring a flight's segment was
    fitted without that flight's date."""
    fits = []
    fit_model = ResidualLogistic.fit_model

    def spy(self, segments):
        fits.append({s.flight[8:18] for s in segments})
        return fit_model(self, segments)

    scored = []
    segment_maxima = ResidualLogistic.segment_maxima

    def spy_maxima(self, segments):
        scored.append((fits[-1], {s.flight[8:18] for s in segments}))
        return segment_maxima(self, segments)

    monkeypatch.setattr(ResidualLogistic, "fit_model", spy)
    monkeypatch.setattr(ResidualLogistic, "segment_maxima", spy_maxima)
    d = ResidualLogistic().fit(_corpus())
    assert len(scored) == 4 and all(not (seen & held) for seen, held in scored)
    # every segment gave one maximum, and the model kept is fitted on every date
    assert sorted(d.maxima_flights_["logistic"]) == sorted(f.flight for f in _corpus())
    assert len(fits[-1]) == 4


def test_a_single_date_cannot_calibrate():
    one_date = [f for f in _corpus() if "2018-07-18" in f.flight]
    with pytest.raises(CalibrationError, match="two dates"):
        ResidualLogistic().fit(one_date)


def test_the_published_rule_is_chosen_again_on_each_pool_of_its_training_flights():
    d = ResidualLogisticPublished().fit(_corpus())
    flights = [f.flight for f in _corpus()]
    every = {f: 1 for f in flights}
    doubled = {f: 2 for f in flights}
    fault_free_only = {f: 1 for f in flights if "no_failure" in f}
    got = d.pool_thresholds([every, doubled, {}, fault_free_only])
    # the whole pool, once or twice over, gives the fit's own threshold; no flight, none
    assert got[0, 0] == got[1, 0] == d.thresholds()[0] and np.isnan(got[2, 0])
    # fault-free flights alone: every one quiet from their largest score on, the last
    # candidate, so half a unit above it
    before = [d.flight_maxima_[f][0] for f in fault_free_only]
    assert got[3, 0] == max(before) + 0.5


def test_a_generic_model_reads_the_studys_features_learned_without_labels():
    """On residual features an outlier model fits (1) on the fault-free rows after the
    warm-up, reads the very features the logistic regression reads, and scores nothing
    in the warm-up, in a batch or a stream."""
    from alfa_bench.methods.outliers import PyODDetector
    from alfa_bench.methods.residual_logistic import residual_features, residuals

    free = [f.sampled for f in _corpus() if f.onset_s is None]
    model = PyODDetector(model="HBOS", features="residuals", rate_hz=RATE).fit(free)
    study = ResidualLogistic().fit(_corpus())
    assert model.signals() == INPUTS
    # the residual models come near the known coefficients of ay and r from these rows
    assert model.weights_["accel_y"][0] == pytest.approx(0.2, abs=0.02)
    assert model.weights_["yaw_rate"][1] == pytest.approx(0.9, abs=0.05)
    s = free[0]
    ours = model._features(s)
    theirs = residual_features(residuals(s.x, model.weights_, model.sigma_), RATE)
    warm = 150                                                    # 15 s at 10 Hz
    assert np.isnan(ours[:warm]).all()
    np.testing.assert_array_equal(ours[warm:], theirs[warm:])
    assert ours.shape[1] == study.center_.size == 25
    score = model.run(s)[0][:, 0]
    assert np.isnan(score[:warm]).all() and np.isfinite(score[warm:]).all()
    model.reset()
    streamed = np.array([model.update(x, np.ones_like(x, bool))[0] for x in s.x])
    np.testing.assert_array_equal(streamed, score)


def test_an_unknown_feature_kind_is_refused_by_name():
    from alfa_bench.methods.outliers import PyODDetector

    with pytest.raises(ValueError, match="features must be one of"):
        PyODDetector(features="raw").check_params()
    with pytest.raises(ValueError, match="window_s would not be read"):
        PyODDetector(features="residuals", window_s=5.0).check_params()
    PyODDetector(features="residuals").check_params()


def test_candidates_that_differ_in_c_alone_build_the_features_once(monkeypatch):
    """A nested selection's candidates that differ in C alone read the same features:
    the second fit takes the first's design (DESIGNS), and gives what a fit of its own
    gives; another positives rule is another design."""
    from alfa_bench.methods.base import learned_digest
    from alfa_bench.methods.fits import fresh_fits
    from alfa_bench.methods.residual_logistic import DESIGNS

    built = []
    design = ResidualLogistic.design
    monkeypatch.setattr(ResidualLogistic, "design",
                        lambda self, segs: built.append(self.C) or design(self, segs))
    with fresh_fits():
        a = ResidualLogistic(C=1.0).fit_model(_corpus())
        b = ResidualLogistic(C=0.01).fit_model(_corpus())
        assert built == [1.0] and len(DESIGNS) == 1
        ResidualLogistic(C=0.01, positives="all").fit_model(_corpus())
        assert built == [1.0, 0.01]
    with fresh_fits():
        alone = ResidualLogistic(C=0.01).fit_model(_corpus())
    assert not np.array_equal(a.coef_, b.coef_)
    assert learned_digest(b) == learned_digest(alone)
