"""Every contract check that fails says which check it is, what it expected, what came
back and what to do: run on detectors each broken in one way, no message is empty."""

import numpy as np
import pytest

from alfa_bench.data import UnknownSignalError
from alfa_bench.methods.base import CalibrationError, Detector
from alfa_bench.methods.contract import CHECKS, ContractError, quick_check
from alfa_bench.methods.extremes import MaximaThresholds


class Sound(Detector):
    def __init__(self, threshold=8.0):
        self.threshold = threshold

    def signals(self):
        return ("pitch_error",)

    def update(self, x, fresh):
        return -x[:1]


class Misspelt(Sound):
    def signals(self):
        return ("rol_error",)


class ReturnsNone(Sound):
    def update(self, x, fresh):
        return None


class KeepsState(Sound):
    def __init__(self, threshold=8.0):
        self.threshold = threshold
        self.buffer = []


class NoThreshold(Detector):
    def __init__(self, gain=1.0):
        self.gain = gain

    def signals(self):
        return ("pitch_error",)

    def update(self, x, fresh):
        return -x[:1] * self.gain


class TwoScores(Sound):
    def update(self, x, fresh):
        return np.r_[-x[:1], x[:1]]


class Unheard(Sound):
    family = "astrology"


class Drifting(Sound):
    """Remembers every flight it ran: not reset, not deterministic across runs."""

    def reset(self):
        self.total_ = getattr(self, "total_", 0.0)
        return self

    def update(self, x, fresh):
        self.total_ += 1.0
        return -x[:1] + self.total_


class Blind(Sound):
    """Scores nothing but NaN: what comes after a change cannot reach it."""

    def update(self, x, fresh):
        return np.array([np.nan])


BROKEN = [Misspelt(), ReturnsNone(), KeepsState(), NoThreshold(), TwoScores(), Unheard(),
          Drifting(), Blind()]


@pytest.mark.slow
def test_every_failing_check_names_itself_what_it_expected_and_what_to_do():
    failed = set()
    for detector in BROKEN:
        for check in CHECKS:
            name = check.__name__.removeprefix("check_")
            try:
                check(detector)
            except AssertionError as e:
                text = str(e)
                assert text.startswith(f"contract check {name}: "), (detector, text)
                # the check's own words, or numpy's comparison (DESIRED, then ACTUAL)
                said = ("expected " in text and "; got " in text) or (
                    "DESIRED:" in text and "ACTUAL:" in text)
                assert said and "\nWhat to do: " in text, (detector, text)
                assert text.rsplit("What to do: ", 1)[1].strip(), (detector, text)
                failed.add(name)
            except (UnknownSignalError, ValueError, TypeError, NotImplementedError) as e:
                assert str(e).strip() and type(detector).__name__ in str(e), (detector, e)
                failed.add(name)
            except Exception as e:   # pytest's skip: the check says why
                assert str(e).strip(), (detector, check, e)
    # each kind of break reached the check that judges it
    assert {"signals_are_in_the_catalogue", "constructor_stores_hyper_parameters_only",
            "outputs_have_the_declared_shape", "its_family_is_one_the_tables_name",
            "each_channel_has_one_positive_threshold", "deterministic",
            "reset_forgets_the_previous_flight", "causal"} <= failed, sorted(failed)


@pytest.mark.parametrize("detector, error, said", [
    (Misspelt(), UnknownSignalError, "names ['rol_error'], which the catalogue does not "
                                     "hold; known: ["),
    (ReturnsNone(), ContractError, "update() returned None for 1 channel(s)"),
    (KeepsState(), ContractError, "got attributes ['buffer', 'threshold']"),
    (TwoScores(), ContractError, "returned 2 value(s) of shape (2,)"),
    (NoThreshold(), ContractError, "has no `threshold` hyper-parameter and no "
                                   "thresholds() of its own"),
], ids=["misspelt signal", "update returns None", "state in __init__", "two scores",
        "no threshold"])
def test_the_quick_checks_say_what_went_wrong(detector, error, said):
    with pytest.raises(error) as e:
        quick_check(detector)
    assert said in str(e.value), str(e.value)
    quick_check(Sound())


class CannotCalibrate(MaximaThresholds, Detector):
    """Its model fits on the check corpus, its thresholds never do."""

    def __init__(self, false_alarm=0.1):
        self.false_alarm = false_alarm

    def signals(self):
        return ("pitch_error",)

    def fit_model(self, segments):
        self.offset_ = 0.0
        return self

    def fit(self, segments):
        self.fit_model(segments)
        raise CalibrationError("CannotCalibrate: too few fault-free flights here")

    def update(self, x, fresh):
        return x[:1] - self.offset_


class LooksAhead(CannotCalibrate):
    """The same, its batch run centred on the whole flight's mean: not causal."""

    def run(self, s, probes=False, start=0, state=None):
        return s.x[start:, :1] - np.nanmean(s.x[:, 0]) - self.offset_, {}


def test_a_detector_the_corpus_cannot_calibrate_is_still_checked(caplog):
    """The checks that need no fit run, and causality on the model's scores: a
    look-ahead is caught although no threshold could be set; the checks left to the
    real flights are named."""
    with pytest.raises(ContractError, match=r"(?s)contract check causal: .*outputs before it"):
        quick_check(LooksAhead())
    caplog.clear()
    quick_check(CannotCalibrate())
    (said,) = [r.getMessage() for r in caplog.records if "left to the real flights" in
               r.getMessage()]
    assert "outputs_have_the_declared_shape" in said and "causal" not in said, said


class Constant(Sound):
    """Scores the same whatever the data: causal, but blind to it."""

    def update(self, x, fresh):
        return np.array([1.0])


def test_a_constant_score_is_told_it_ignores_the_data_not_that_it_looks_ahead():
    with pytest.raises(ContractError) as e:
        quick_check(Constant())
    said = str(e.value)
    assert "contract check causal: " in said and "do not depend on the data" in said, said
    assert "no look-ahead" not in said, said
    # a detector that looks ahead is still told so
    with pytest.raises(ContractError) as e:
        quick_check(LooksAhead())
    assert "no look-ahead" in str(e.value) and "do not depend" not in str(e.value)
