"""Fits kept in a process (methods/fits.py): keyed by the code that fitted them, never by
a class's name alone; bounded; and never read by the contract's refit check."""

import itertools

import numpy as np
import pytest

from alfa_bench.data.flight import parse_flight_name
from alfa_bench.methods import fits, labelled_segments, make_detector, training_segments
from alfa_bench.methods.base import Detector, source_digest
from alfa_bench.methods.contract import check_a_refit_is_a_fresh_fit
from alfa_bench.methods.nested_selection import INNER_FITS

LEVEL = """
import numpy as np

from alfa_bench.methods.base import Detector
from alfa_bench.methods.fits import kept_fit


class Level(Detector):
    calibrated = True

    def __init__(self, threshold=1.0):
        self.threshold = threshold

    def signals(self):
        return ("pitch_error",)

    def fit(self, segments):
        kept_fit(self, segments, self._fit, ("level_",))
        return self

    def _fit(self, segments):
        self.level_ = {level}

    def update(self, x, fresh):
        return np.abs(x[:1] - self.level_)
"""


def _level(module: str, level: float) -> type[Detector]:
    """A class ``Level`` of ``module`` whose fit learns ``level``, typed as into a
    notebook (no file holds its source)."""
    namespace = {"__name__": module}
    exec(LEVEL.format(level=level), namespace)
    return namespace["Level"]


@pytest.fixture(scope="module")
def segments(corpus_flights):
    flights = [f for f in corpus_flights.values() if f.fault is not None]
    return training_segments(_level("notebook", 0.0)(), flights, 1.0)


def test_a_class_of_the_same_name_never_gets_another_class_fit(segments):
    """A fit is kept by its class's module, name and code: a class of the same name in
    another module, or one redefined with other code, is fitted anew; the same code
    (defined again as it was) takes its own fit."""
    fits.MODEL_FITS.clear()
    assert _level("notebook", 1.0)().fit(segments).level_ == 1.0
    assert _level("other_module", 3.0)().fit(segments).level_ == 3.0
    assert _level("notebook", 2.0)().fit(segments).level_ == 2.0       # redefined
    assert len(fits.MODEL_FITS) == 3
    # the same code in another module: another key, the same fit
    _level("third_module", 1.0)().fit(segments)
    assert len(fits.MODEL_FITS) == 4
    assert _level("notebook", 2.0)().fit(segments).level_ == 2.0
    assert len(fits.MODEL_FITS) == 4


def test_the_code_of_a_notebook_class_is_its_own_fit_not_the_seal_around_it():
    """Without a file to read, a class's code is its functions' bytecode: its own fit's,
    not the wrapper every fit is sealed in (:func:`~alfa_bench.methods.base._sealed`)."""
    source = """
from alfa_bench.methods.base import Detector


class Fixed(Detector):
    def signals(self):
        return ("pitch_error",)

    def fit(self, segments):
        self.level_ = {level}
        return self

    def update(self, x, fresh):
        return x[:1]
"""
    made = []
    for level in (1.0, 2.0):
        namespace = {"__name__": "notebook"}
        exec(source.format(level=level), namespace)
        made.append(namespace["Fixed"])
    assert source_digest(made[0]) != source_digest(made[1])


def test_a_store_keeps_the_fits_last_used_up_to_its_bound():
    store = fits.KeptFits(2)
    for key in "abc":
        store.put(key, key.upper())
    assert len(store) == 2 and store.get("a") is None
    assert store.get("b") == "B"          # now the last used: c goes next
    store.put("d", "D")
    assert store.get("c") is None and store.get("b") == "B"
    with fits.fresh_fits():                 # empty within, given back after
        assert store.get("b") is None
        store.put("e", "E")
        assert store.get("e") == "E"
    assert store.get("e") is None and store.get("b") == "B" and len(store) == 2


def test_the_inner_fits_stay_within_their_bound_and_change_nothing(corpus_flights,
                                                                    monkeypatch):
    """INNER_FITS keeps no more than its bound; a selection whose inner fits outgrow it
    fits them again, and chooses and learns the same."""
    flights = [f for f in corpus_flights.values() if f.fault is not None]
    scored = sorted({str(parse_flight_name(n)["date"]) for n in corpus_flights})[0]
    training = [f for f in flights if str(parse_flight_name(f.id)["date"]) != scored]

    def fitted() -> dict:
        nested = make_detector("nested_selection", {
            "detector": "pyod", "params": {"model": "HBOS"},
            "grid": {"window_s": [1.0, 2.0]}})
        return nested.fit(labelled_segments(nested, training)).fitted()

    INNER_FITS.clear()
    unbounded = fitted()
    assert len(INNER_FITS) > 2
    INNER_FITS.clear()
    monkeypatch.setattr(INNER_FITS, "kept", 2)
    assert fitted() == unbounded
    assert len(INNER_FITS) == 2


_DRAWS = itertools.count(1)


class Restless(Detector):
    """Its fit learns another offset each time: not deterministic, which a fit kept in
    the process would hide."""

    calibrated = True

    def __init__(self, threshold=8.0):
        self.threshold = threshold

    def signals(self):
        return ("pitch_error",)

    def fit(self, segments):
        fits.kept_fit(self, segments, self._fit, ("offset_",))
        return self

    def _fit(self, segments):
        self.offset_ = float(next(_DRAWS))

    def update(self, x, fresh):
        return np.abs(x[:1]) - self.offset_


def test_the_refit_check_fits_anew_and_catches_a_fit_that_is_not_deterministic():
    fits.MODEL_FITS.clear()
    with pytest.raises(AssertionError, match="(?s)contract check a_refit_is_a_fresh_fit: "
                       "expected a refit to learn what a fresh fit learns.*seed every"):
        check_a_refit_is_a_fresh_fit(Restless())
    check_a_refit_is_a_fresh_fit(_level("notebook", 1.0)())
