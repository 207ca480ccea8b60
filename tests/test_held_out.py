"""No fit ever sees the group it scores: for every configured calibrated run, for a
supervised detector learning from labelled flights, and a fold that lets one in stops
the run."""

import numpy as np
import pytest
from config_runs import CONFIG, one_run_per

import alfa_bench.analysis.detections as detections
from alfa_bench.analysis import detect_all, folds
from alfa_bench.analysis.held_out import HeldOutError, group_labels
from alfa_bench.methods import REGISTRY, Detector, Labelled, make_detector

CALIBRATION = {"group_by": "date", "margin_s": 1.0}
# what reaches a run's fit depends on its detector (a nested selection's on its base
# too) and its grouping, not on its other parameters: one run of each
CALIBRATED = one_run_per(
    lambda spec: (spec["detector"], (spec.get("params") or {}).get("detector"),
                  repr(spec.get("calibration"))),
    [n for n, spec in CONFIG["methods"].items() if REGISTRY[spec["detector"]].calibrated])


class PeakRoll(Detector):
    """A supervised toy: alarms on |roll| above the largest seen before any onset of its
    labelled training flights; it records what it learned from."""

    calibrated = True
    supervised = True
    rate_hz = 10.0

    def __init__(self, margin: float = 1.0):
        self.margin = margin

    def signals(self):
        return ("roll",)

    def channels(self):
        return ("roll",)

    def channel_outputs(self):
        return ("roll",)

    def fit(self, segments):
        assert all(isinstance(s, Labelled) for s in segments)
        before = [np.abs(s.sampled.x[s.sampled.t < (np.inf if s.onset_s is None
                                                      else s.onset_s), 0]) for s in segments]
        self.threshold_ = float(max(b.max() for b in before if b.size)) + self.margin
        self.classes_ = sorted({s.fault_class for s in segments})
        return self

    def fitted(self):
        return {"threshold": self.threshold_, "classes": self.classes_}

    def thresholds(self):
        self._check_fitted("threshold_")
        return np.array([self.threshold_])

    def reset(self):
        self._check_fitted("threshold_")
        return self

    def update(self, x, fresh):
        return np.abs(x[:1])


def spied(monkeypatch, detector):
    """``detector``, handed to every detect_all, with the flights of each fit kept (of
    its class's, since every fold fits a clone)."""
    seen = []
    fit = type(detector).fit

    def spy(self, segments):
        seen.append({s.flight for s in segments})
        return fit(self, segments)

    monkeypatch.setattr(type(detector), "fit", spy)
    monkeypatch.setattr(detections, "make_detector", lambda *a, **k: detector)
    return seen


def assert_held_out(records, seen, manifest, group_by="date"):
    group = dict(zip(manifest["flight"], group_labels(manifest, group_by), strict=True))
    fits = dict(zip(dict.fromkeys(r["calibration"]["fold"] for r in records), seen,
                    strict=True))
    for r in records:
        fold = r["calibration"]["fold"]
        assert r["calibration"]["group_by"] == group_by
        assert group[r["flight"]] == fold
        assert fits[fold] and all(group[f] != fold for f in fits[fold]), (r["flight"], fold)
        assert set(r["calibration"]["flights"]) == fits[fold]


@pytest.mark.slow
@pytest.mark.parametrize("run", CALIBRATED)
def test_no_fit_of_a_configured_run_sees_the_group_it_scores(run, corpus_flights,
                                                             corpus_manifest, monkeypatch):
    """Each run's own grouping, where it sets one (the public study's: by recording)."""
    spec = CONFIG["methods"][run]
    seen = spied(monkeypatch, make_detector(spec["detector"], spec.get("params")))
    records = [r for r, _ in detect_all(run, spec, corpus_flights, corpus_manifest, CALIBRATION)]
    assert records and len(seen) == len({r["calibration"]["fold"] for r in records})
    assert_held_out(records, seen, corpus_manifest,
                    spec.get("calibration", {}).get("group_by", "date"))
    # only a run that declares it learns from labels (a nested selection) gets them
    assert all(r["calibration"]["supervised"] == REGISTRY[spec["detector"]].supervised
               for r in records)


def test_a_supervised_detector_learns_from_labelled_flights_of_other_dates(
        corpus_flights, corpus_manifest, monkeypatch):
    seen = spied(monkeypatch, PeakRoll())
    records = [r for r, _ in detect_all("peak", {"detector": "peak"}, corpus_flights,
                                        corpus_manifest, CALIBRATION)]
    assert_held_out(records, seen, corpus_manifest)
    for r in records:
        cal = r["calibration"]
        assert cal["supervised"]
        # whole faulty flights reach it, with their class: it learns what a fault is
        classes = {corpus_manifest.set_index("flight").at[f, "fault_class"] for f in cal["flights"]}
        assert set(cal["fitted"]["classes"]) == classes and classes - {"none"}


def test_a_fold_that_lets_the_scored_date_in_stops_the_run(corpus_flights, corpus_manifest,
                                                           monkeypatch):
    def leaky(train, group_by):
        return {g: (held, [*training, held[0]])
                for g, (held, training) in folds(train, group_by).items()}

    monkeypatch.setattr(detections, "folds", leaky)
    for detector, spec in ((PeakRoll(), {"detector": "peak"}),
                           (make_detector("glrt_residuals"), {"detector": "glrt_residuals"})):
        monkeypatch.setattr(detections, "make_detector", lambda *a, d=detector, **k: d)
        with pytest.raises(HeldOutError, match="scored group"):
            list(detect_all("leaky", spec, corpus_flights, corpus_manifest, CALIBRATION,
                            failures=[]))


def test_a_recording_is_the_flight_names_timestamp_and_its_parts_share_a_fold(
        corpus_manifest):
    by_recording = folds(corpus_manifest, "recording")
    labels = group_labels(corpus_manifest, "recording")
    assert set(by_recording) == set(labels[corpus_manifest["ground_truth"]])
    for name, (scored, training) in by_recording.items():
        assert all(f.startswith(f"carbonZ_{name}_") for f in scored)
        assert not any(f.startswith(f"carbonZ_{name}_") for f in training)
    # the synthetic corpus has two recordings of 2018-10-05: one fold each, not one
    assert len(by_recording) > len(folds(corpus_manifest, "date"))
    with pytest.raises(ValueError, match="recording"):
        folds(corpus_manifest, "day")
