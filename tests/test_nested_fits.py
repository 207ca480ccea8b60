"""Nested selection keeps its inner fits across the workflow's folds: the fit without
dates {o, d} serves both the fold scoring o and the one scoring d, and changes nothing."""

from pathlib import Path

import yaml

from alfa_bench.data.flight import parse_flight_name
from alfa_bench.methods import labelled_segments, make_detector

REPO = Path(__file__).resolve().parent.parent


def _nested():
    spec = yaml.safe_load((REPO / "config/config.yaml").read_text())["methods"][
        "residual_bank_nested"]
    params = {**spec["params"], "grid": {"false_alarm": [0.05, 0.2]}}
    return make_detector(spec["detector"], params)


def test_the_folds_share_inner_fits_and_get_what_fresh_fits_give(corpus_flights):
    date = {n: str(parse_flight_name(n)["date"]) for n in corpus_flights}
    dates = sorted(set(date.values()))
    assert len(dates) >= 3
    shared, made_fresh = _nested(), 0
    for scored in dates:
        training = [f for n, f in corpus_flights.items()
                    if date[n] != scored and f.fault is not None]
        segments = labelled_segments(shared, training)
        fresh = _nested().fit(segments)
        assert shared.fit(segments).fitted() == fresh.fitted()
        made_fresh += len(fresh.inner_fits_)
    # each inner fit without two dates comes twice over the folds, and is made once
    assert 0 < len(shared.inner_fits_) < made_fresh
