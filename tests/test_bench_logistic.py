"""The project's own supervised entry (methods/bench_logistic.py): its blocks, its fits
kept across a nested selection, and the selection's inner fits on labelled flights of
the inner training dates only."""

import numpy as np
import pytest
from config_runs import CONFIG

from alfa_bench.data import Sampled
from alfa_bench.data.flight import parse_flight_name
from alfa_bench.methods import base, bench_logistic, fits, labelled_segments, make_detector, physics
from alfa_bench.methods.bench_logistic import BenchLogistic
from alfa_bench.methods.nested_selection import INNER_FITS


def _date(flight: str) -> str:
    return str(parse_flight_name(flight)["date"])


def test_the_nested_run_fits_each_candidate_on_labelled_flights_of_other_dates(
        corpus_flights, monkeypatch):
    """Nested selection over a supervised base gives each candidate the labelled flights
    of the inner training dates, never one of the date it is scored on, and the chosen
    classifier all the training flights."""
    spec = CONFIG["methods"]["bench_logistic"]
    grid = {"features": [["study"], ["study", "physics"]], "C": [0.1]}
    nested = make_detector(spec["detector"], {**spec["params"], "grid": grid})
    seen = []
    real = BenchLogistic.fit_model
    monkeypatch.setattr(BenchLogistic, "fit_model",
                        lambda self, segs: seen.append(segs) or real(self, segs))
    flights = list(corpus_flights.values())
    training = labelled_segments(nested, flights)
    INNER_FITS.clear()
    fits.MODEL_FITS.clear()
    nested.fit(training)
    assert all(isinstance(s, base.Labelled) for segs in seen for s in segs)
    assert any(s.onset_s is not None for segs in seen for s in segs)
    dates = {_date(f.flight) for f in training}
    # every inner fit misses a training date at least; the last fit has them all
    assert all({_date(s.flight) for s in segs} < dates for segs in seen[:-1])
    assert {s.flight for s in seen[-1]} == {f.flight for f in training}
    inner = nested.fitted()["inner"]
    assert [c["values"]["features"] for c in inner] == grid["features"]
    assert all(c["scored"] > 0 for c in inner)


def test_a_kept_classifier_fit_is_the_fresh_fit(corpus_flights):
    """Two classifier fits made anew learn the same, and a fit taken from MODEL_FITS is
    a fresh fit, token and all; a flight labelled otherwise is other data, not the same
    fit."""
    features = ("study", "bank", "physics")
    segments = labelled_segments(BenchLogistic(features=features), list(corpus_flights.values()))
    with fits.fresh_fits():
        one = BenchLogistic(features=features).fit(segments)
    with fits.fresh_fits():
        two = BenchLogistic(features=features).fit(segments)
    assert list(vars(one)) == list(vars(two))
    assert base.learned_digest(one) == base.learned_digest(two)
    assert base.fit_token(one) == base.fit_token(two)
    fits.MODEL_FITS.clear()
    BenchLogistic(features=features).fit(segments)
    made = len(fits.MODEL_FITS)              # the model, and those of its inner folds
    kept = BenchLogistic(features=features).fit(segments)
    assert len(fits.MODEL_FITS) == made > 0
    assert list(vars(kept)) == list(vars(one))
    assert base.learned_digest(kept) == base.learned_digest(one)
    assert base.fit_token(kept) == base.fit_token(one)
    faulty = next(i for i, s in enumerate(segments) if s.onset_s is not None)
    moved = list(segments)
    moved[faulty] = base.Labelled(segments[faulty].sampled, segments[faulty].onset_s + 1.0,
                                  segments[faulty].fault_class)
    assert base.segment_digest(moved[faulty]) != base.segment_digest(segments[faulty])


def test_a_segments_physics_block_is_computed_once_and_is_what_it_computes(monkeypatch):
    """The physics block is fitted on nothing: the candidates and folds of a nested
    selection read one computation of it per segment and first step, the same as a fresh
    one, and cannot write into it; a new segment of the same values is computed anew."""
    n = 400
    rng = np.random.default_rng(1)
    x = rng.normal(size=(n, len(physics.SIGNALS_READ)))

    def segment():
        return Sampled(t=np.arange(n) / physics.RATE_HZ, x=x.copy(),
                       fresh=np.ones_like(x, bool), names=physics.SIGNALS_READ)

    s = segment()
    fresh = physics.features_of(s.columns(physics.SIGNALS_READ))
    expected = np.nan_to_num(np.column_stack([fresh[f] for f in physics.FEATURES]), nan=0.0)
    made = []
    real = physics.features_of
    monkeypatch.setattr(physics, "features_of", lambda *a: made.append(a) or real(*a))
    one, two = (bench_logistic._physics_block(s, 0) for _ in range(2))
    assert len(made) == 1 and one is two and np.array_equal(one, expected)
    with pytest.raises(ValueError, match="read-only"):
        one[0, 0] = 1.0
    bench_logistic._physics_block(s, 5)
    other = segment()
    assert np.array_equal(bench_logistic._physics_block(other, 0), expected)
    assert len(made) == 3


@pytest.mark.parametrize("features", [("bank",), ("study", "study"), ("study", "wind")])
def test_blocks_must_be_distinct_known_and_hold_the_study(features):
    with pytest.raises(ValueError, match="distinct blocks"):
        BenchLogistic(features=features)._blocks()


def test_a_nan_row_does_not_spoil_the_attitude_gains_after_it():
    """A gain sums its window's products: a NaN row at a fresh step once made every
    later sum NaN in a whole-flight run, while a stream forgets it (seen in the
    classifier's streaming check)."""
    n = 600
    rng = np.random.default_rng(0)
    x = rng.normal(size=(n, len(physics.SIGNALS_READ)))
    x[300] = np.nan
    s = Sampled(t=np.arange(n) / physics.RATE_HZ, x=x, fresh=np.ones_like(x, bool),
                names=physics.SIGNALS_READ)
    feats = physics.features_of(s)
    for name in ("roll_rate_gain_drop", "pitch_rate_gain_drop", "roll_asymmetry"):
        assert np.isfinite(feats[name][-50:]).all(), name


def test_a_selection_no_candidate_can_be_scored_in_takes_the_first_and_says_so(
        corpus_flights, caplog):
    """On three dates a classifier without the emergency-trajectory positives cannot be
    fitted without one of them: the first candidate of the grid is taken, the record
    and the log say why, and the run still scores."""
    spec = CONFIG["methods"]["bench_logistic_no_emr"]
    nested = make_detector(spec["detector"], spec["params"])
    scored = "2018-07-18"
    training = [f for n, f in corpus_flights.items() if _date(n) != scored]
    INNER_FITS.clear()
    with caplog.at_level("WARNING"):
        fitted = nested.fit(labelled_segments(nested, training)).fitted()
    assert not any(c["scored"] for c in fitted["inner"])
    assert fitted["chosen"] == nested.candidates()[0]
    assert fitted["chosen_by"].startswith("grid order")
    assert "the first of the grid is taken" in caplog.text
    assert np.isfinite(nested.thresholds()).all()
