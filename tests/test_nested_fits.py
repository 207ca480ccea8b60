"""Nested selection keeps its inner fits across the workflow's folds (for the process,
since each fold fits a clone): the fit without dates {o, d} serves both the fold
scoring o and the one scoring d, and changes nothing."""

import json

from config_runs import CONFIG

from alfa_bench.data.flight import parse_flight_name
from alfa_bench.methods import labelled_segments, make_detector
from alfa_bench.methods.nested_selection import INNER_FITS


def _nested():
    spec = CONFIG["methods"]["residual_bank_nested"]
    params = {**spec["params"], "grid": {"false_alarm": [0.05, 0.2]}}
    return make_detector(spec["detector"], params)


def test_the_folds_share_inner_fits_and_get_what_fresh_fits_give(corpus_flights):
    date = {n: str(parse_flight_name(n)["date"]) for n in corpus_flights}
    dates = sorted(set(date.values()))
    assert len(dates) >= 3
    shared, made_fresh, fitted = _nested(), 0, []
    INNER_FITS.clear()
    for scored in dates:
        training = [f for n, f in corpus_flights.items()
                    if date[n] != scored and f.fault is not None]
        fitted.append(shared.fit(labelled_segments(shared, training)).fitted())
    made_shared = len(INNER_FITS)
    for scored, kept in zip(dates, fitted, strict=True):
        INNER_FITS.clear()
        training = [f for n, f in corpus_flights.items()
                    if date[n] != scored and f.fault is not None]
        fresh = _nested().fit(labelled_segments(shared, training))
        assert fresh.fitted() == kept
        made_fresh += len(INNER_FITS)
    # each inner fit without two dates comes twice over the folds, and is made once
    assert 0 < made_shared < made_fresh


def test_candidates_apart_in_thresholds_alone_share_one_fit(corpus_flights, monkeypatch):
    """false_alarm sets the residual bank's thresholds only: the candidates that differ
    in it alone are fitted and run once per inner fold, and choose what fitting each
    apart chooses."""
    from alfa_bench.methods.residual_bank import ResidualBank

    date = {n: str(parse_flight_name(n)["date"]) for n in corpus_flights}
    scored = sorted(set(date.values()))[0]
    training = [f for n, f in corpus_flights.items() if date[n] != scored and f.fault is not None]
    fits = []
    real_fit = ResidualBank.fit
    monkeypatch.setattr(ResidualBank, "fit",
                        lambda self, s: fits.append(self.window_s) or real_fit(self, s))
    nested = _nested()
    nested.grid = {"window_s": [0.5, 1.0], "false_alarm": [0.05, 0.1, 0.2]}
    INNER_FITS.clear()
    segments = labelled_segments(nested, training)
    shared = nested.fit(segments).fitted()
    together = len(fits)
    monkeypatch.setattr(ResidualBank, "threshold_params", ())
    fits.clear()
    INNER_FITS.clear()
    apart = _nested()
    apart.grid = nested.grid
    assert apart.fit(segments).fitted() == shared
    # apart: each of the 6 candidates per inner date that holds flights scored, and the
    # last fit; together: one per window and date where that fit stands (the other
    # members of a group whose first cannot be fitted are tried on their own)
    held_dates, rest = divmod(len(fits) - 1, 6)
    assert held_dates >= 2 and rest == 0
    unfit = sum(len(c["unfit"]) for c in shared["inner"] if c["values"]["false_alarm"] == 0.05)
    assert together == 2 * held_dates + 1 + 2 * unfit < len(fits)


def test_a_generic_model_is_fitted_once_per_candidate_and_dates(corpus_flights, monkeypatch):
    """Nested selection of a PyOD model fits it on each set of dates inside the
    out-of-sample maxima of several larger sets: each such fit is made once
    (MODEL_FITS), and the choice, maxima and thresholds are those of fitting each anew."""
    from alfa_bench.methods import fits, outliers

    spec = CONFIG["methods"]["pyod_knn_nested"]
    grid = {"window_s": [1.0], "params": [{"n_neighbors": 3}, {"n_neighbors": 5}]}
    flights = [f for f in corpus_flights.values() if f.fault is not None]
    calls = []
    real = outliers.PyODDetector._fit_estimator
    monkeypatch.setattr(outliers.PyODDetector, "_fit_estimator",
                        lambda self, e, X: calls.append(len(X)) or real(self, e, X))

    def fitted() -> dict:
        nested = make_detector(spec["detector"], {**spec["params"], "grid": grid})
        INNER_FITS.clear()
        fits.MODEL_FITS.clear()
        calls.clear()
        return nested.fit(labelled_segments(nested, flights)).fitted()

    kept = fitted()
    made = len(calls)
    monkeypatch.setattr(fits.MODEL_FITS, "kept", 0)
    assert fitted() == kept
    assert 0 < made < len(calls)
    assert not len(fits.MODEL_FITS)


def test_a_candidate_never_fitted_is_recorded_unscored_in_valid_json(corpus_flights):
    """A candidate that no training date can fit (here a window longer than any
    flight) is named unfit on every date, with no share, and the record stays JSON."""
    flights = [f for f in corpus_flights.values() if f.fault is not None]
    nested = make_detector("nested_selection", {
        "detector": "pyod", "params": {"model": "HBOS"},
        "grid": {"window_s": [1.0, 1e5]}})
    fitted = nested.fit(labelled_segments(nested, flights)).fitted()
    never = fitted["inner"][1]
    assert never["scored"] == 0 and never["share"] is None and never["unfit"]
    assert fitted["chosen"] == {"window_s": 1.0}
    json.dumps(fitted, allow_nan=False)
