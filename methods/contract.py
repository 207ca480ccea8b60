"""The detector contract, as checks any detector can be run through, in or out of the
package (scikit-learn's ``check_estimator`` and ``parametrize_with_checks`` are the
model).

Each check takes an unfitted detector, copies it, fits the copy where it is calibrated
(on the fault-free data of a small synthetic corpus, :mod:`alfa_bench.data.synthetic`)
and raises ``AssertionError`` where the contract fails:

- the constructor stores its hyper-parameters and nothing else; learned state ends
  in ``_``; a calibrated detector refuses to run unfitted; a ``run()`` of its own
  takes the base class's arguments;
- fitted values are JSON-ready, outputs have the declared shape, each channel names
  the measured signal it scores, and each has one positive threshold (a channel
  alarms exactly when its score is above it, :meth:`~.base.Detector.alarms`);
- probes are named once and change nothing; a batch ``run`` equals stepping
  ``update`` (scores to rounding, so the same alarms); runs are deterministic, and
  ``reset`` forgets the previous flight; a run continued from a snapshot (forked)
  equals the run from t = 0; where hyper-parameters set only the thresholds,
  re-thresholding a fit for new values equals fitting with them;
- a refit is a fresh fit: one instance fitted on other data, then on the check's
  (anew, not from the fits kept in the process before, :mod:`.fits`), gives what a new
  one fitted on the check's gives, and a state taken under the first fit is refused
  under the second; per-flight maxima that do not vary give a
  :class:`~.base.CalibrationError`, from the point fit and the pool fit alike, never
  an infinite or NaN threshold;
- it is causal: changing the data after time *t* changes no output before *t*; and
  changes some after it (scores the data does not reach are named as such, not as a
  look-ahead).

A plugin's own tests run them all with one decorator::

    from alfa_bench.methods.contract import parametrize_with_checks

    @parametrize_with_checks([Cusum()])
    def test_cusum(detector, check):
        check(detector)
"""

from __future__ import annotations

import copy
import functools
import inspect
import json
import logging
import shutil
import tempfile
from dataclasses import replace
from functools import cache
from pathlib import Path

import numpy as np

from alfa_bench.data import SIGNALS, UnknownSignalError, load_flight, sample
from alfa_bench.data.synthetic import rename_flight, write_corpus

from .base import (
    FAMILIES,
    CalibrationError,
    Detector,
    NotFittedError,
    StaleStateError,
    Trace,
    continue_forks,
    fit_token,
    forks,
    run_detector,
    training_segments,
)
from .extremes import MaximaThresholds
from .fits import fresh_fits

__all__ = ["CHECKS", "QUICK_CHECKS", "ContractError", "parametrize_with_checks",
           "quick_check"]

log = logging.getLogger(__name__)


class ContractError(ValueError):
    """A detector breaks the contract: which check, what it found, and what to do."""

#: the corpus flight the checks run a detector on
_FLIGHT = "carbonZ_2018-07-18-15-53-31_1_engine_failure"


@cache
def _corpus() -> Path:
    """The synthetic corpus, written once per process to a folder of its own."""
    processed = Path(tempfile.mkdtemp(prefix="alfa-bench-checks-")) / "processed"
    write_corpus(processed)
    return processed


def _fit(detector: Detector, leave_out: int = 0) -> Detector:
    """``detector`` fitted on the corpus, less its first ``leave_out`` flights."""
    training = [load_flight(p) for p in sorted(_corpus().iterdir())[leave_out:]]
    return detector.fit(training_segments(detector, training, margin_s=1.0))


_FITTED: dict = {}


def _fitted(detector: Detector) -> Detector:
    """A fitted copy of ``detector`` that has never run (fits are kept per process)."""
    key = (type(detector), repr(detector.get_params()))
    if key not in _FITTED:
        try:
            _FITTED[key] = _fit(copy.deepcopy(detector))
        except CalibrationError as e:       # kept too (its words): each check asks again
            _FITTED[key] = CalibrationError(*e.args)
    if isinstance(_FITTED[key], CalibrationError):
        raise CalibrationError(*_FITTED[key].args)
    return copy.deepcopy(_FITTED[key])


def _flight():
    return load_flight(_corpus() / _FLIGHT)


def _skip(reason: str):
    import pytest  # the checks run under pytest (parametrize_with_checks)

    pytest.skip(reason)


def _assert_same(a, b, upto=None, what: str = "the two runs"):
    sl = slice(None) if upto is None else slice(0, upto)
    for name in ("t", "score", "alarm"):
        # NaN == NaN here
        np.testing.assert_array_equal(getattr(a, name)[sl], getattr(b, name)[sl],
                                      err_msg=f"{what}: {name} differs")


def _expect(ok, expected: str, got) -> None:
    """Fail the check unless ``ok``, saying what was expected and what came back."""
    if not ok:
        raise AssertionError(f"expected {expected}; got {got}")


class _Advice(AssertionError):
    """A check's failure that calls for other advice than the check's own: ``todo``."""

    def __init__(self, said: str, todo: str):
        super().__init__(said)
        self.todo = todo


#: what to do about scores the data does not reach
_READ_THE_DATA = ("its scores do not depend on the data: compute each step's score from "
                  "the signals it reads (a score the data cannot change cannot detect a "
                  "fault), and check that update() does not return NaN on every step")


def _expect_the_data_reaches(a: np.ndarray, b: np.ndarray, where: str) -> None:
    """Fail the check, with :data:`_READ_THE_DATA`, where the scores ``a`` of the check
    flight equal those ``b`` of the flight with its data changed ``where``: no other
    check of the run could fail then."""
    if np.array_equal(a, b, equal_nan=True):
        raise _Advice(f"expected scores that change {where} where the data does; got the "
                      "same scores (is every score NaN or constant?)", _READ_THE_DATA)


def _check(todo: str):
    """A contract check whose failure says which check it is, what it expected, what came
    back, and ``todo``: what to do about it (never an empty message)."""
    def wrap(check):
        name = check.__name__.removeprefix("check_")

        @functools.wraps(check)
        def checked(detector: Detector) -> None:
            try:
                check(detector)
            except AssertionError as e:
                said = str(e).strip() or "a condition failed without a message"
                raise AssertionError(f"contract check {name}: {said}\nWhat to do: "
                                     f"{getattr(e, 'todo', todo)}") from e
        return checked
    return wrap


def check_signals_are_in_the_catalogue(detector: Detector) -> None:
    """Every signal :meth:`~.base.Detector.signals` names is in the catalogue: else
    :class:`~alfa_bench.data.UnknownSignalError`, listing the catalogue."""
    unknown = [n for n in detector.signals() if n not in SIGNALS]
    if unknown:
        raise UnknownSignalError(
            f"{type(detector).__name__}.signals() names {unknown}, which the catalogue "
            f"does not hold; known: {sorted(SIGNALS)} (docs/python.md lists each one)")


@_check("store each __init__ argument as an attribute of the same name and nothing "
        "else; set learned state in fit() (or reset() for running state), in attributes "
        "ending in _")
def check_constructor_stores_hyper_parameters_only(detector: Detector) -> None:
    d = copy.deepcopy(detector)
    _expect(set(vars(d)) == set(d.get_params()),
            f"__init__ to store its parameters {sorted(d.get_params())} and nothing else",
            f"attributes {sorted(vars(d))}")
    before = set(vars(d))
    d.warm()
    _expect(set(vars(d)) == before, "warm() to set nothing on the detector",
            f"attributes {sorted(set(vars(d)) - before)}")
    # the fit every check shares, made from a copy of the detector as d is: what its
    # fit learned is the attributes it has beyond d's
    fitted = _fitted(detector)
    fitted.reset()
    learned = set(vars(fitted)) - before
    _expect(all(a.endswith("_") for a in learned),
            "every attribute fit() or reset() sets to end in _",
            sorted(a for a in learned if not a.endswith("_")))
    _expect(learned or not d.calibrated, "a calibrated detector to learn in fit()",
            "no learned attribute")


@_check("give run() the base class's signature: run(self, s, probes=False, start=0, "
        "state=None)")
def check_run_takes_the_base_arguments(detector: Detector) -> None:
    """A ``run()`` override takes ``(s, probes, start, state)``, as the workflow calls
    it (a snapshot of None means it is never given a state)."""
    names = list(inspect.signature(type(detector).run).parameters)
    _expect(names[:5] == ["self", "s", "probes", "start", "state"],
            "run(self, s, probes, start, state)", f"run({', '.join(names)})")


@_check("an uncalibrated detector learns nothing (fitted() is {}); a calibrated one "
        "raises NotFittedError, naming fit(), when run before fit()")
def check_calibrated_detectors_refuse_to_run_unfitted(detector: Detector) -> None:
    d = copy.deepcopy(detector)
    if not d.calibrated:
        _expect(d.fitted() == {}, "fitted() == {} for an uncalibrated detector", d.fitted())
        return
    try:
        run_detector(d, _flight())
    except NotFittedError as e:
        _expect("fit" in str(e), "a NotFittedError that names fit()", repr(str(e)))
    else:
        raise AssertionError("expected NotFittedError from a calibrated detector run "
                             "before fit(); got a run")


@_check("return plain numbers, strings, lists and dicts from fitted(): no arrays, no "
        "NaN or infinity (convert with .tolist(), float())")
def check_fitted_values_are_json_ready(detector: Detector) -> None:
    fitted = _fitted(detector).fitted()
    try:
        json.dumps(fitted, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise AssertionError(f"expected fitted() to be JSON-ready; got {e}") from e


@_check("return from update() one score per channel of channels(), an array of that "
        "length; a run() of its own returns an array (steps, channels)")
def check_outputs_have_the_declared_shape(detector: Detector) -> None:
    d = _fitted(detector)
    s = sample(_flight(), d.signals(), d.rate_hz)
    score, _ = d.run(s)       # before the thresholds, which the next check judges
    want = (s.t.size, len(d.channels()))
    _expect(np.shape(score) == want, f"scores of shape {want} (steps, channels "
            f"{list(d.channels())})", f"shape {np.shape(score)}")


@_check(f"set the class attribute family to one of {list(FAMILIES)}")
def check_its_family_is_one_the_tables_name(detector: Detector) -> None:
    _expect(detector.family in FAMILIES, f"a family among {list(FAMILIES)}",
            repr(detector.family))


@_check("return from channel_outputs() one signal per channel, each among signals() "
        "and the catalogue (alfa_bench.data.SIGNALS)")
def check_each_channel_names_the_measured_signal_it_scores(detector: Detector) -> None:
    outputs, channels = detector.channel_outputs(), detector.channels()
    _expect(len(outputs) == len(channels), f"one output per channel of {list(channels)}",
            list(outputs))
    _expect(set(outputs) <= set(detector.signals()) and set(outputs) <= set(SIGNALS),
            f"outputs among signals() {list(detector.signals())}",
            sorted(set(outputs) - set(detector.signals())) or sorted(set(outputs) - set(SIGNALS)))


@_check("return from thresholds() one finite, positive threshold per channel, and "
        "leave alarms() to the base class (a channel alarms when its score is above it)")
def check_each_channel_has_one_positive_threshold(detector: Detector) -> None:
    d = _fitted(detector)
    trace = run_detector(d, _flight())
    want = (len(d.channels()),)
    _expect(trace.threshold.shape == want, f"thresholds of shape {want}",
            f"shape {trace.threshold.shape}")
    _expect(np.all(np.isfinite(trace.threshold) & (trace.threshold > 0)),
            "finite, positive thresholds", trace.threshold)
    _expect(trace.alarm.dtype == bool, "alarms() to return booleans", trace.alarm.dtype)
    np.testing.assert_array_equal(trace.alarm, d.alarms(trace.score),
                                  err_msg="alarms differ from score > threshold")


@_check("name each probe once, fix the names at reset(), compute each at least once, "
        "and keep probes() free of side effects")
def check_probes_are_named_once_and_do_not_change_the_run(detector: Detector) -> None:
    d, flight = _fitted(detector), _flight()
    plain, probed = run_detector(d, flight), run_detector(d, flight, probes=True)
    _assert_same(plain, probed, what="the run with probes and without")
    _expect(plain.probes == {}, "no probes kept when none are asked for",
            sorted(plain.probes))
    _expect(len(probed.probes) == len(set(probed.probes)), "each probe named once",
            list(probed.probes))
    for name, values in probed.probes.items():
        _expect(values.shape == probed.t.shape, f"probe {name} on every step",
                f"shape {values.shape}")
        _expect(np.isfinite(values).any(), f"probe {name} computed at least once",
                "NaN on every step")


@_check("make a run() of its own give update()'s scores and probes step by step (or "
        "remove it: the base class steps update())")
def check_batch_run_equals_streaming(detector: Detector) -> None:
    """A detector's own run() (batch or compiled) gives the scores and probes of update()
    step by step to rounding, and the same alarms wherever a score is not within
    rounding of its threshold, on the check flight and on the same flight with a NaN
    row half-way (NaN where update()'s are). (A non-causal reference's run() uses the
    whole flight by design: skipped.)"""
    d = _fitted(detector)
    if not d.causal:
        _skip("a non-causal reference: its run() uses the whole flight by design")
    s = sample(_flight(), d.signals(), d.rate_hz)
    # and a flight with a NaN row half-way, as a signal that has not started gives one
    holed = replace(s, x=s.x.copy(), fresh=s.fresh.copy())
    holed.x[s.t.size // 2] = np.nan
    for flight, where in [(s, ""), (holed, " with a NaN row half-way")]:
        score, probes = d.run(flight, probes=True)
        ref_score, ref_probes = Detector.run(d, flight, probes=True)
        np.testing.assert_allclose(score, ref_score, rtol=1e-9, atol=1e-9,
                                   err_msg=f"run()'s scores differ from update()'s{where}")
        thr = d.thresholds()
        tie = np.abs(ref_score - thr) <= 1e-9 * np.maximum(1.0, thr)
        np.testing.assert_array_equal(d.alarms(score)[~tie], d.alarms(ref_score)[~tie],
                                      err_msg=f"run()'s alarms differ from update()'s{where}")
        _expect(list(probes) == list(ref_probes), f"run()'s probes {list(ref_probes)}",
                list(probes))
        for name in probes:
            np.testing.assert_allclose(probes[name], ref_probes[name], rtol=1e-9, atol=1e-9,
                                       err_msg=f"probe {name} differs from update()'s{where}")


@_check("make snapshot() hold every attribute update() changes (the default copies "
        "them all), or return None: the run is then never continued")
def check_forked_run_equals_run(detector: Detector) -> None:
    """Continued from a :meth:`~.base.Detector.snapshot` (:func:`~.base.forks`), a
    flight that shares a prefix with the one forked gives the run from t = 0: the
    same alarms, and scores and probes to rounding. The flight here is the check
    flight with its data after 0.6 of its length scrambled; it is forked at 0.3 and
    0.6 of its length. A detector whose snapshot is None is run from t = 0 (its
    forks are empty): skipped."""
    d = _fitted(detector)
    flight = _flight()
    cut_s = 0.6 * flight.duration_s
    at = forks(d, flight, [0.3 * flight.duration_s, cut_s], probes=True)
    if not at:
        _skip("its snapshot() is None: forked runs run from t = 0")
    with tempfile.TemporaryDirectory() as tmp:
        other = load_flight(_scrambled_after(flight, cut_s, Path(tmp)))
    for fork in at.values():
        _expect(fork.shared_by(sample(other, d.signals(), d.rate_hz), probes=True),
                "a fork taken before the change to be shared by the changed flight",
                "not shared")
        forked = run_detector(d, other, probes=True, fork=fork)
        whole = run_detector(d, other, probes=True)
        np.testing.assert_allclose(forked.score, whole.score, rtol=1e-9, atol=1e-9,
                                   err_msg="the forked run's scores differ from the run's")
        np.testing.assert_array_equal(forked.alarm, whole.alarm,
                                      err_msg="the forked run's alarms differ from the run's")
        _expect(list(forked.probes) == list(whole.probes), f"probes {list(whole.probes)}",
                list(forked.probes))
        for name in whole.probes:
            np.testing.assert_allclose(forked.probes[name], whole.probes[name],
                                       rtol=1e-9, atol=1e-9,
                                       err_msg=f"the forked run's probe {name} differs")
    # the scrambled data must reach the detector, or the fork could not differ
    _expect_the_data_reaches(whole.score, run_detector(d, flight).score,
                             f"after {cut_s:.1f} s")


@_check("make a run_many() of its own give each item's run() (or remove it)")
def check_many_continued_runs_equal_each_run(detector: Detector) -> None:
    """:meth:`~.base.Detector.run_many` over flights continued from their forks
    (:func:`~.base.continue_forks`, as the injected grid is scored) gives each one's
    :meth:`~.base.Detector.run` from its fork, and the run from t = 0. Flights here: the
    check flight, scrambled after 0.6 and after 0.8 of its length, each continued from
    its fork at 0.3 or 0.6. A detector whose snapshot is None: skipped."""
    d = _fitted(detector)
    flight = _flight()
    at = forks(d, flight, [0.3 * flight.duration_s, 0.6 * flight.duration_s])
    if not at:
        _skip("its snapshot() is None: forked runs run from t = 0")
    with tempfile.TemporaryDirectory() as tmp:
        others = [load_flight(rename_flight(
            _scrambled_after(flight, share * flight.duration_s, Path(tmp) / str(share)),
            _FLIGHT.replace("_1_", f"_{i + 2}_"))) for i, share in enumerate((0.6, 0.8))]
    for forked in ({t: f} for t, f in at.items()):
        continued = continue_forks(d, others, forked)
        _expect(sorted(continued) == sorted(o.id for o in others),
                f"a run of each flight {sorted(o.id for o in others)}", sorted(continued))
        for other in others:
            np.testing.assert_allclose(run_detector(d, other, continued=continued[other.id]).score,
                                       run_detector(d, other).score,
                                       rtol=1e-9, atol=1e-9,
                                       err_msg=f"run_many()'s scores of {other.id} differ "
                                               "from its run's")


@_check("list in threshold_params only the parameters that set nothing but the "
        "thresholds, and set the thresholds from them in rethreshold()")
def check_rethreshold_equals_fit(detector: Detector) -> None:
    """For each of its :attr:`~.base.Detector.threshold_params`, a fitted detector given
    another value and :meth:`~.base.Detector.rethreshold` equals one fitted with it:
    what fit learned, and the run. A detector that declares none has nothing to
    check."""
    if not detector.threshold_params:
        return
    d = _fitted(detector)
    for name in detector.threshold_params:
        value = getattr(d, name)
        other = value / 2 if isinstance(value, float) else value
        refit = _fit(type(d)(**{**d.get_params(), name: other}))
        moved = copy.deepcopy(d)
        setattr(moved, name, other)
        _expect(moved.rethreshold() is moved, "rethreshold() to return self", "another "
                "object")
        _expect(moved.fitted() == refit.fitted(), f"with {name} = {other!r}, rethreshold() "
                f"to learn what a fit learns: {refit.fitted()}", moved.fitted())
        _assert_same(run_detector(moved, _flight()), run_detector(refit, _flight()),
                     what=f"with {name} = {other!r}, the re-thresholded and refitted runs")
        if other != value:       # the value must reach the thresholds
            _expect(not np.array_equal(moved.thresholds(), d.thresholds()),
                    f"other thresholds with {name} = {other!r}", "the same thresholds")


@_check("let fit() learn from its data alone, the same each time: start from nothing "
        "learned (the base class forgets learned attributes; keep no other cache on the "
        "instance), and seed every random draw from the parameters")
def check_a_refit_is_a_fresh_fit(detector: Detector) -> None:
    """One instance fitted on other data (the corpus less two flights), run, then fitted
    on the check's, equals a new one fitted on the check's: what fit learned, its
    :func:`~.base.fit_token` and the run. The refit is made anew
    (:func:`~.fits.fresh_fits`): a fit kept in the process before would be the other
    one again, and hide a fit that is not deterministic. A state taken under the first fit
    is refused under the second, where the two fits learned differently. An
    uncalibrated detector has nothing to check."""
    if not detector.calibrated:
        return
    d = copy.deepcopy(detector)
    try:
        _fit(d, leave_out=2)
    except CalibrationError:
        first = None                   # the check's data alone then: a failed fit first
    else:
        run_detector(d, _flight())
        first = fit_token(d), forks(d, _flight(), [0.5 * _flight().duration_s])
    with fresh_fits():
        _fit(d)
    fresh = _fitted(detector)
    _expect(d.fitted() == fresh.fitted(), f"a refit to learn what a fresh fit learns: "
            f"{fresh.fitted()}", d.fitted())
    _expect(fit_token(d) == fit_token(fresh), "a refit's fit token to be a fresh fit's",
            "another token")
    _assert_same(run_detector(d, _flight()), run_detector(fresh, _flight()),
                 what="the refitted and the freshly fitted runs")
    if first is not None and first[1] and first[0] != fit_token(d):
        fork = next(iter(first[1].values()))
        try:
            fork.continued(d, sample(_flight(), d.signals(), d.rate_hz), probes=False)
        except StaleStateError:
            pass
        else:
            raise AssertionError("expected StaleStateError for a state taken under "
                                 "another fit; got a continued run")


@_check("leave the per-flight maxima thresholds to MaximaThresholds, which raises "
        "CalibrationError where they do not vary")
def check_maxima_that_do_not_vary_cannot_calibrate(detector: Detector) -> None:
    """Thresholds from per-flight maxima (:class:`~.extremes.MaximaThresholds`): maxima
    that are all equal (a constant score) raise :class:`~.base.CalibrationError` from
    :meth:`~.base.Detector.rethreshold` and from
    :meth:`~.base.Detector.pool_thresholds` alike. Other detectors have nothing to
    check."""
    if not isinstance(detector, MaximaThresholds):
        return
    for attempt in ("rethreshold", "pool_thresholds"):
        d = _fitted(detector)
        d.maxima_ = {c: [2.5] * max(len(m), 5) for c, m in d.maxima_.items()}
        d.maxima_flights_ = {c: [f"f{i}" for i in range(len(m))] for c, m in d.maxima_.items()}
        try:
            d.rethreshold() if attempt == "rethreshold" else d.pool_thresholds(
                [{"f0": 2, "f1": 3}])
        except CalibrationError:
            continue
        raise AssertionError(f"expected CalibrationError from {attempt}() on maxima "
                             "that do not vary; got a threshold")


@_check("seed every random draw from the parameters (a seed parameter), and reset "
        "every running state in reset()")
def check_deterministic(detector: Detector) -> None:
    d, flight = _fitted(detector), _flight()
    _assert_same(run_detector(d, flight), run_detector(d, flight), what="two runs")


@_check("set every attribute update() changes back in reset(), and change nothing "
        "fit() learned while running")
def check_reset_forgets_the_previous_flight(detector: Detector) -> None:
    d = _fitted(detector)
    other = load_flight(next(p for p in sorted(_corpus().iterdir()) if "no_failure" in p.name))
    run_detector(d, other)
    fresh = _fitted(detector)
    _expect(fresh.fitted() == d.fitted(), f"running to leave what fit learned: "
            f"{fresh.fitted()}", d.fitted())
    _assert_same(run_detector(d, _flight()), run_detector(fresh, _flight()),
                 what="a run after another flight's and a fresh one")


def _scrambled(cell: str) -> str:
    try:
        return repr(float(cell) * -3.0 + 17.0)
    except ValueError:
        return cell


def _scrambled_after(flight, cut_s: float, tmp: Path) -> Path:
    """A copy of the check flight in ``tmp`` whose mavros rows after ``cut_s`` (flight
    clock) have every field but time, seq and stamp scrambled."""
    altered = shutil.copytree(_corpus() / _FLIGHT, tmp / _FLIGHT)
    cut_ns = flight.t0_ns + int(cut_s * 1e9)
    for f in altered.glob("*mavros*.csv"):
        lines = f.read_text().splitlines()
        out = [lines[0]]
        for line in lines[1:]:
            if int(line.split(",", 1)[0]) > cut_ns:
                cells = line.split(",")
                line = ",".join(cells[:3] + [_scrambled(c) for c in cells[3:]])
            out.append(line)
        f.write_text("\n".join(out) + "\n")
    return altered


def _model_only(detector: Detector) -> Detector | None:
    """``detector``'s model fitted on the corpus without thresholds
    (:meth:`~.extremes.MaximaThresholds.fit_model`), for a detector the corpus cannot
    calibrate: its scores can still be run. None where it has no such fit or that
    fails too."""
    if not hasattr(detector, "fit_model"):
        return None
    d = copy.deepcopy(detector)
    training = [load_flight(p) for p in sorted(_corpus().iterdir())]
    try:
        return d.fit_model(training_segments(d, training, margin_s=1.0))
    except Exception:   # its model alone cannot fit either: the real flights will say
        return None


def _scores(d: Detector, flight) -> Trace:
    """The scores of ``d`` (a model without thresholds) over ``flight``, as a trace
    without alarms."""
    s = sample(flight, d.signals(), d.rate_hz)
    return Trace(t=s.t, score=d.run(s)[0], alarm=np.zeros((s.t.size, 0), bool),
                 channels=d.channels(), threshold=np.array([]))


@_check("compute each step's score from that step and earlier ones only (no look-ahead, "
        "no whole-flight statistics), and return it from update() every step")
def check_causal(detector: Detector) -> None:
    """Changing the data after time t changes no output before t (a detector that
    declares itself non-causal, a reference row, is skipped). A detector the check
    corpus cannot calibrate is checked on its scores, its model fitted without
    thresholds, where it has such a fit (``fit_model``)."""
    if not detector.causal:
        _skip("a non-causal reference, ranked apart")
    try:
        d, run = _fitted(detector), run_detector
    except CalibrationError:
        d, run = _model_only(detector), _scores
        if d is None:
            raise
    flight = _flight()
    base = run(d, flight)
    cut_s = 0.7 * float(base.t[-1])
    with tempfile.TemporaryDirectory() as tmp:
        changed = run(d, load_flight(_scrambled_after(flight, cut_s, Path(tmp))))
    before = int(np.searchsorted(base.t, cut_s, side="right"))
    _expect(before > 0, "grid steps before the change", "none")
    _assert_same(base, changed, upto=before,
                 what=f"with the data changed after {cut_s:.1f} s, the outputs before it")
    # the alteration must reach the detector, or this check could not fail
    _expect_the_data_reaches(base.score[before:], changed.score[before:],
                             f"after {cut_s:.1f} s")


#: every check, in the order they run
CHECKS = (
    check_signals_are_in_the_catalogue,
    check_constructor_stores_hyper_parameters_only,
    check_run_takes_the_base_arguments,
    check_calibrated_detectors_refuse_to_run_unfitted,
    check_fitted_values_are_json_ready,
    check_outputs_have_the_declared_shape,
    check_each_channel_names_the_measured_signal_it_scores,
    check_its_family_is_one_the_tables_name,
    check_each_channel_has_one_positive_threshold,
    check_probes_are_named_once_and_do_not_change_the_run,
    check_batch_run_equals_streaming,
    check_forked_run_equals_run,
    check_many_continued_runs_equal_each_run,
    check_rethreshold_equals_fit,
    check_a_refit_is_a_fresh_fit,
    check_maxima_that_do_not_vary_cannot_calibrate,
    check_deterministic,
    check_reset_forgets_the_previous_flight,
    check_causal,
)


#: the checks :func:`quick_check` runs: the contract's shape, and causality
QUICK_CHECKS = (
    check_signals_are_in_the_catalogue,
    check_constructor_stores_hyper_parameters_only,
    check_run_takes_the_base_arguments,
    check_each_channel_names_the_measured_signal_it_scores,
    check_outputs_have_the_declared_shape,
    check_each_channel_has_one_positive_threshold,
    check_causal,
)


def quick_check(detector: Detector) -> None:
    """Run :data:`QUICK_CHECKS` on ``detector`` (left as it is) on one synthetic flight,
    as :func:`alfa_bench.evaluate` does before scoring it (about a second).

    A calibrated detector that cannot be fitted on the synthetic corpus
    (:class:`~.base.CalibrationError`) still gets every check that needs no fit, and
    the causality check on its scores where its model fits without thresholds
    (``fit_model``); the checks left to the real flights are logged, which will say
    whether it calibrates. A non-causal one is not checked for causality.

    Raises
    ------
    UnknownSignalError
        Where :meth:`~.base.Detector.signals` names a signal the catalogue lacks.
    ContractError
        Naming the check that fails, what it expected, what came back, and what to
        do."""
    left = []
    for check in QUICK_CHECKS:
        if check is check_causal and not detector.causal:
            continue
        try:
            check(detector)
        except CalibrationError as e:
            left.append((check.__name__.removeprefix("check_"), e))
            continue
        except AssertionError as e:      # the check said what, and what to do
            raise ContractError(f"{type(detector).__name__} fails the {e}\n(The contract: "
                                "docs/adding-a-method.md; to score it anyway, "
                                "evaluate(..., check=False))") from e
        except (ValueError, TypeError, NotImplementedError) as e:
            raise ContractError(
                f"{type(detector).__name__} fails the contract check "
                f"{check.__name__.removeprefix('check_')}: {type(e).__name__}: {e}\n"
                "What to do: see docs/adding-a-method.md (the contract); to score it "
                "anyway, evaluate(..., check=False)") from e
    if left:
        log.warning("%s cannot be fitted on the synthetic check corpus (%s): checks %s "
                    "are left to the real flights", type(detector).__name__, left[0][1],
                    ", ".join(name for name, _ in left))


def parametrize_with_checks(detectors):
    """A pytest decorator running every check of :data:`CHECKS` on every detector of
    ``detectors`` (unfitted instances; a dict gives them ids), as test parameters
    ``detector`` and ``check``."""
    import pytest

    named = detectors if isinstance(detectors, dict) else {
        f"{type(d).__name__}{i}" if len(detectors) > 1 else type(d).__name__: d
        for i, d in enumerate(detectors)}
    cases = [(d, c) for d in named.values() for c in CHECKS]
    ids = [f"{name}-{c.__name__.removeprefix('check_')}" for name in named for c in CHECKS]
    return pytest.mark.parametrize("detector, check", cases, ids=ids)
