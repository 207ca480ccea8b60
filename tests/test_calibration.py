"""Calibration without leakage: folds, fault-free segments, and what records say."""

import dataclasses
from collections import ChainMap

import numpy as np
import pandas as pd
import pytest

from alfa_bench.analysis import detect_all, folds
from alfa_bench.data import build_manifest, load_flight
from alfa_bench.data.inject import InjectedGrid
from alfa_bench.data.manifest import manifest_of, manifest_row
from alfa_bench.methods import fault_free_segments, make_detector

CALIBRATION = {"group_by": "date", "margin_s": 1.0}


@pytest.fixture(scope="module")
def manifest(corpus):
    return build_manifest(corpus)


@pytest.fixture(scope="module")
def flights(corpus, manifest):
    return {f: load_flight(corpus / f) for f in manifest["flight"]}


@pytest.mark.parametrize("group_by", ["date", "flight"])
def test_every_labelled_flight_is_scored_once_by_a_fold_that_never_saw_it(manifest,
                                                                            group_by):
    out = folds(manifest, group_by)
    scored = [f for s, _ in out.values() for f in s]
    assert sorted(scored) == sorted(manifest.loc[manifest["ground_truth"], "flight"])
    date = dict(zip(manifest["flight"], manifest["date"], strict=True))
    for held, training in out.values():
        assert not set(held) & set(training)
        if group_by == "date":
            assert not {date[f] for f in held} & {date[f] for f in training}


def test_a_single_group_cannot_calibrate(manifest):
    one_day = manifest[manifest["date"] == manifest["date"].iloc[0]]
    with pytest.raises(ValueError, match="at least two"):
        folds(one_day, "date")


def test_segments_stop_before_onset_and_refuse_unlabelled_flights(flights):
    det = make_detector("glrt_residuals")
    names = sorted(flights)
    segments = fault_free_segments(det, [flights[n] for n in names], margin_s=1.0)
    for name, s in zip(names, segments, strict=True):
        onset = flights[name].fault.onset_s
        if onset is None:
            assert s.t[-1] > 70.0                       # the whole fault-free flight
        else:
            assert s.t[-1] < onset - 1.0 <= s.t[-1] + 1 / det.rate_hz
    unlabelled = dataclasses.replace(flights[names[0]], fault=None)
    with pytest.raises(ValueError, match="no ground truth"):
        fault_free_segments(det, [unlabelled], margin_s=1.0)


def test_records_name_their_calibration_flights_and_fitted_values(corpus, manifest):
    flights = {f: load_flight(corpus / f) for f in manifest["flight"]}
    spec = {"detector": "glrt_residuals", "params": {}}
    records = [r for r, _ in detect_all("glrt_arx", spec, flights, manifest, CALIBRATION)]
    assert sorted(r["flight"] for r in records) == sorted(manifest["flight"])
    date = dict(zip(manifest["flight"], manifest["date"], strict=True))
    for r in records:
        cal = r["calibration"]
        assert r["flight"] not in cal["flights"] and cal["flights"]
        assert date[r["flight"]] == cal["fold"]
        assert all(date[f] != cal["fold"] for f in cal["flights"])
        assert np.all(np.isfinite(cal["fitted"]["threshold"]))
        assert cal["group_by"] == "date" and cal["margin_s"] == 1.0


def test_a_fold_that_cannot_calibrate_is_a_failure_row_not_the_end(flights, manifest):
    """One method, one fold it cannot fit: those flights become failure rows saying what
    to change, the other folds are scored; strict (no failure list) still stops."""
    # P_F = 1.5e-4 needs 6667 fault-free samples: the folds that leave out two flights
    # of the synthetic corpus have about 5600, the others about 7500
    spec = {"detector": "glrt_residuals", "params": {"false_alarm": 1.5e-4}}
    failures = []
    records = [r for r, _ in detect_all("glrt", spec, flights, manifest, CALIBRATION,
                                        failures)]
    failed = {f["flight"] for f in failures}
    assert records and failed and all(f["stage"] == "calibration" for f in failures)
    assert all("calibration.group_by: flight" in f["error"] for f in failures)
    assert {r["flight"] for r in records} | failed == set(manifest["flight"])
    assert not {r["flight"] for r in records} & failed
    with pytest.raises(ValueError, match="cannot resolve P_F"):
        list(detect_all("glrt", spec, flights, manifest, CALIBRATION))


def test_a_single_date_is_a_failure_row_for_every_flight(flights, manifest):
    one_day = manifest[manifest["date"] == manifest["date"].iloc[0]]
    failures = []
    spec = {"detector": "glrt_residuals", "params": {}}
    assert list(detect_all("glrt", spec, flights, one_day, CALIBRATION, failures)) == []
    assert sorted(f["flight"] for f in failures) == sorted(one_day["flight"])
    assert all("at least two date groups" in f["error"] for f in failures)


@pytest.mark.parametrize("group_by", ["date", "flight"])
def test_an_injected_flight_is_scored_by_the_fold_that_left_its_source_out(
        flights, manifest, tmp_path, group_by):
    """Under either grouping (leaving out one flight used to leave every injected
    flight without a fold, so none was scored)."""
    free = manifest.loc[manifest["fault_class"] == "none", "flight"]
    grid = InjectedGrid({f: flights[f] for f in free}, manifest, tmp_path, ["roll"],
                        [{"kind": "drift", "magnitude": 0.5}], [0.4])
    injected = manifest_of([manifest_row(grid[n], sha) for n, sha in grid.sha256.items()])
    scored = pd.concat([manifest, injected], ignore_index=True)
    spec = {"detector": "glrt_residuals", "params": {}}
    records = {r["flight"]: r for r, _ in detect_all(
        "glrt", spec, ChainMap(flights, grid), scored,
        {**CALIBRATION, "group_by": group_by}, calibrate_on=manifest)}
    source = dict(zip(injected["flight"], injected["fault_source"], strict=True))
    assert set(source) <= set(records)
    column = {"date": "date", "flight": "flight"}[group_by]
    own = dict(zip(manifest["flight"], manifest[column], strict=True))
    for name, src in source.items():
        cal = records[name]["calibration"]
        assert cal["fold"] == own[src] and src not in cal["flights"]
        assert cal["fitted"] == records[src]["calibration"]["fitted"]
