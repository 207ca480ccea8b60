r"""Hyper-parameters chosen by an inner leave-one-date-out, inside each fit.

A registered detector (``detector``, with fixed ``params``) has a ``grid`` of
candidate values for some of its hyper-parameters; their product is the set of
:math:`C` candidate configurations. The workflow fits this detector once per scored
date, on labelled flights of the other dates only (:class:`~.base.Labelled`, so it is
``supervised``: it reads their labels to score the candidates). Inside that fit, for
each candidate :math:`c` and each training date :math:`d`, the base detector with
:math:`c` is fitted on the fault-free data of the training dates other than
:math:`d` (whole fault-free flights, the others up to onset less ``margin_s``), or on
their labelled flights if the base is supervised (a classifier's own inner
leave-one-date-out then runs inside, on those dates alone), and run on the flights of
:math:`d`. Each held-out flight counts as right when

- a fault flight's first alarm lies in :math:`[\tau, \tau + D]` (``deadline_s``), the
  primary scoring rule;
- a fault-free flight never alarms;

and :math:`c` scores the share of held-out flights it gets right, pooled over the
training dates (a date without which :math:`c` cannot be fitted goes unscored, and is
named). Flights flown on an emergency trajectory are left out of the inner
scores with ``score_emr`` False (the headline subset's rule; they still calibrate).
The highest share wins, ties to the first candidate in grid order (which also wins,
said so in the record and the log, where no candidate could be scored: too few dates or
flights to fit any without one); the base detector
with it is then fitted on every training flight (their fault-free data, or the
flights labelled) and scores the held-out date. So the scored date reaches neither
the choice nor the fit, and the records say, per fold, which configuration scored and
how many were tried
(:meth:`NestedSelection.fitted`).

Every candidate must read the same signals and give the same channels; a grid that
changes them (a different set of models) is refused.

Across the workflow's folds, one detector is fitted once per scored date, and the
inner fit without dates :math:`\{o, d\}` comes twice: scoring :math:`o` with :math:`d`
held out, and scoring :math:`d` with :math:`o` held out. Each inner fit is therefore
kept, keyed by the candidate and the exact data it was fitted on (a digest of every
segment's samples), and given again when the same data comes back; fits are
deterministic, so this changes no result, and halves the inner fits. They are kept for
the process (:data:`INNER_FITS`, keyed by the candidate's code and hyper-parameters and
its data, :func:`~.fits.fit_key`), not in the detector: each fold fits a clone of it,
and a fit starts from nothing (:meth:`~.base.Detector.fit`). Candidates that
differ only in hyper-parameters that set the thresholds
(:attr:`~.base.Detector.threshold_params`, such as a false-alarm rate) give the same
scores: one of them is fitted and run, the others take its fit re-thresholded
(:meth:`~.base.Detector.rethreshold`, which the contract checks against a fit).
"""

from __future__ import annotations

import copy
import itertools
import logging

import numpy as np

from alfa_bench.data import Sampled
from alfa_bench.data.flight import parse_flight_name

from .base import (
    CalibrationError,
    Detector,
    Labelled,
    clone,
    free_part,
    leave_one_date_out,
)
from .fits import KeptFits, fit_key, segments_data

__all__ = ["INNER_FITS", "NestedSelection", "held_out_right"]

log = logging.getLogger(__name__)

#: the inner fits made in this process (the fitted detector, or the
#: :class:`~.base.CalibrationError` it could not be fitted with), by the candidate's
#: code and hyper-parameters and its data (:func:`~.fits.fit_key`): the 256 last used,
#: twice the distinct inner fits of the workflow's largest run (12 candidates, each
#: without every pair of ALFA's 5 dates); and in the folder :func:`~.fits.use_files`
#: names, where the fit is arrays and JSON
INNER_FITS = KeptFits(256, "inner")


def _sharing(made: list[Detector]) -> list[list[int]]:
    """The candidates by group, in grid order: those whose hyper-parameters differ in
    :attr:`~.base.Detector.threshold_params` alone share their fits and scores."""
    groups: dict[str, list[int]] = {}
    for i, d in enumerate(made):
        rest = {k: v for k, v in d.get_params().items() if k not in d.threshold_params}
        groups.setdefault(repr(sorted(rest.items())), []).append(i)
    return list(groups.values())


def held_out_right(first_alarm_s: float | None, onset_s: float | None,
                   deadline_s: float) -> bool:
    """Whether a flight is scored right: a fault's first alarm within the deadline after
    onset, no alarm on a fault-free flight."""
    if onset_s is None:
        return first_alarm_s is None
    return first_alarm_s is not None and onset_s <= first_alarm_s <= onset_s + deadline_s


class NestedSelection(Detector):
    """A registered detector with hyper-parameters chosen by an inner
    leave-one-date-out (module docstring).

    Parameters
    ----------
    detector : str
        The base detector's registry name.
    params : dict
        Its fixed hyper-parameters.
    grid : dict of str to list
        Candidate values per hyper-parameter; every combination is tried.
    deadline_s : float
        :math:`D` of the inner score.
    margin_s : float
        Fault-free data of a faulty flight ends this long before onset.
    score_emr : bool
        Whether flights on an emergency trajectory count in the inner scores.

    Attributes
    ----------
    chosen_ : dict
        The winning values of the grid's hyper-parameters.
    chosen_by_ : str
        How: by the inner scores, or by grid order where none could be scored.
    inner_ : list of dict
        Per candidate: its values, the held-out flights scored, how many were right,
        their share (None where none was scored), and the training dates without which
        it could not be fitted.
    base_ : Detector
        The base detector with ``chosen_``, fitted on every training flight.
    """

    calibrated = True
    supervised = True

    def __init__(self, detector="residual_bank", params=None, grid=None, deadline_s=5.0,
                 margin_s=1.0, score_emr=False):
        self.detector = detector
        self.params = params
        self.grid = grid
        self.deadline_s = deadline_s
        self.margin_s = margin_s
        self.score_emr = score_emr

    # -- the base detector and its candidates -------------------------------------------

    def _make(self, values: dict) -> Detector:
        from . import make_detector  # the registry imports this module

        return make_detector(self.detector, {**(self.params or {}), **values})

    def warm(self) -> None:
        """Warm the base detector (its grid changes its values, not its library)."""
        self._make({}).warm()

    def candidates(self) -> list[dict]:
        """Every combination of the grid's values, in grid order."""
        grid = self.grid or {}
        names = list(grid)
        return [dict(zip(names, combo, strict=True))
                for combo in itertools.product(*(grid[n] for n in names))]

    def _reference(self) -> Detector:
        """The base with the first candidate: what every candidate must agree with."""
        return self._make(self.candidates()[0])

    @property
    def rate_hz(self) -> float:
        return self._reference().rate_hz

    @property
    def causal(self) -> bool:
        return self._reference().causal

    @property
    def family(self) -> str:
        return self._reference().family

    def signals(self) -> tuple[str, ...]:
        return self._reference().signals()

    def channels(self) -> tuple[str, ...]:
        return self._reference().channels()

    def channel_outputs(self) -> tuple[str, ...]:
        return self._reference().channel_outputs()

    def check_params(self) -> None:
        """The base detector is registered, ``params`` and ``grid`` name its
        hyper-parameters only (the grid a list of values for each), and every candidate
        builds, keeps the base's signals, channels and rate, and passes the base's own
        :meth:`~.base.Detector.check_params`: a nested run that cannot be fitted is
        refused by the dry run, not in its job. Each error names the base and the key."""
        from . import make_detector  # the registry imports this module

        where = f"nested selection of {self.detector!r}"
        try:
            names = make_detector(self.detector).param_names()
        except KeyError as e:
            raise ValueError(f"{where}: detector: {e.args[0]}") from None
        for part, keys in (("params", self.params or {}), ("grid", self.grid or {})):
            unknown = [k for k in keys if k not in names]
            if unknown:
                raise ValueError(f"{where}: {part} key {unknown[0]!r} is not a "
                                 f"hyper-parameter of {self.detector!r}; it has {names}")
        for key, values in (self.grid or {}).items():
            if not isinstance(values, list) or not values:
                raise ValueError(f"{where}: grid key {key!r} must list its candidate values "
                                 f"(YAML [a, b, ...]); got {values!r}")
        try:
            made = self._check_grid()
        except TypeError as e:
            raise ValueError(f"{where}: grid: {e}") from None
        for values, candidate in zip(self.candidates(), made, strict=True):
            try:
                candidate.check_params()
            except ValueError as e:
                raise ValueError(f"{where}: grid candidate {values}: {e}") from None

    def _check_grid(self) -> list[Detector]:
        candidates = self.candidates()
        if not candidates:
            raise ValueError("nested selection needs at least one candidate in its grid")
        made = [self._make(c) for c in candidates]
        for c, d in zip(candidates, made, strict=True):
            if (d.signals(), d.channels(), d.rate_hz) != (made[0].signals(), made[0].channels(),
                                                          made[0].rate_hz):
                raise ValueError(f"candidate {c} changes the signals, channels or rate of "
                                 f"{self.detector!r}: a grid may only tune, not reshape")
        return made

    # -- fitting ------------------------------------------------------------------------

    def _training(self, base: Detector,
                  flights: list[Labelled]) -> list[Sampled] | list[Labelled]:
        """What ``base`` is fitted on of ``flights``: all of them, labelled, if it is
        supervised; else their fault-free segments, as the workflow calibrates."""
        if base.supervised:
            return flights
        return [s for s in (free_part(f, self.margin_s) for f in flights) if s.t.size]

    def _scored(self, flight: Labelled) -> bool:
        return self.score_emr or not str(
            parse_flight_name(flight.flight)["label"]).endswith("with_emr_traj")

    def fit(self, segments: list[Labelled]) -> NestedSelection:
        for attr in ("chosen_", "inner_", "base_"):
            self.__dict__.pop(attr, None)
        made = self._check_grid()
        folds = leave_one_date_out(segments)
        if len(folds) < 2:
            raise CalibrationError(f"nested selection needs training flights of two dates or "
                                   f"more; found {len(folds)}")
        digest = dict(zip(map(id, segments), segments_data(segments), strict=True))
        candidates, groups = self.candidates(), _sharing(made)
        tally = [{"scored": 0, "right": 0, "unfit": []} for _ in made]
        for d, training, held in folds:
            held = [f for f in held if self._scored(f)]
            if not held:
                continue
            data = [digest[id(f)] for f in training]
            for group in groups:
                fits = {i: self._inner_fit(i, group[0], made, data, training) for i in group}
                for i in group:
                    if isinstance(fits[i], CalibrationError):
                        log.info("nested selection: %s cannot be fitted without %s: %s",
                                 candidates[i], d, fits[i])
                        tally[i]["unfit"].append(d)
                live = [i for i in group if not isinstance(fits[i], CalibrationError)]
                if not live:
                    continue
                # one run for the group (its members differ in their thresholds only), of
                # every held-out flight at once
                runs = fits[live[0]].run_many([(f.sampled, 0, None) for f in held])
                for f, (score, _) in zip(held, runs, strict=True):
                    for i in live:
                        alarm = fits[i].alarms(score).any(axis=1)
                        first = float(f.t[np.argmax(alarm)]) if alarm.any() else None
                        tally[i]["right"] += held_out_right(first, f.onset_s, self.deadline_s)
                        tally[i]["scored"] += 1
        inner = [{"values": values, "scored": t["scored"], "right": t["right"],
                  "share": t["right"] / t["scored"] if t["scored"] else None,
                  "unfit": t["unfit"]} for values, t in zip(candidates, tally, strict=True)]
        best = max(range(len(inner)), key=lambda i: (
            -1.0 if inner[i]["share"] is None else inner[i]["share"], -i))
        if not any(c["scored"] for c in inner):
            log.warning("nested selection of %s: no candidate could be fitted and scored on "
                        "any training date (%s); the first of the grid is taken",
                        self.detector, sorted({u for c in inner for u in c["unfit"]}))
        self.inner_ = inner
        self.chosen_by_ = ("inner leave-one-date-out" if any(c["scored"] for c in inner)
                           else "grid order: no candidate could be scored without a date")
        self.chosen_ = inner[best]["values"]
        self.base_ = made[best].fit(self._training(made[best], segments))
        log.info("nested selection of %s: %s, %d of %d held-out flights right (of %d "
                 "candidates)", self.detector, self.chosen_, inner[best]["right"],
                 inner[best]["scored"], len(inner))
        return self

    def _inner_fit(self, i: int, first: int, made: list[Detector], data: list[str],
                   training: list[Labelled]) -> Detector | CalibrationError:
        """Candidate ``i`` fitted on ``training`` (whose segments' digests are ``data``),
        or the :class:`~.base.CalibrationError` it cannot be fitted with; kept in
        :data:`INNER_FITS`. A candidate that differs from candidate ``first`` of its
        group in :attr:`~.base.Detector.threshold_params` alone is that fit,
        re-thresholded."""
        key = self._inner_key(made[i], data)
        fit = INNER_FITS.get(key)
        if fit is not None:
            return fit
        shared = INNER_FITS.get(self._inner_key(made[first], data)) if i != first else None
        try:
            if shared is None or isinstance(shared, CalibrationError):
                fit = clone(made[i]).fit(self._training(made[i], training))
            else:
                fit = copy.deepcopy(shared)
                for name in type(fit).threshold_params:
                    setattr(fit, name, getattr(made[i], name))
                fit.rethreshold()
        except CalibrationError as e:   # too little data without the date: it goes unscored
            fit = e
        INNER_FITS.put(key, fit)
        return fit

    def _inner_key(self, candidate: Detector, data: list[str]) -> str | None:
        """The key of ``candidate``'s fit on the training flights whose digests are
        ``data``: those labelled flights if it is supervised, else their fault-free
        parts less ``margin_s`` (:meth:`_training`)."""
        if not candidate.supervised:
            data = {"fault_free_before_onset_less_s": self.margin_s, "of": data}
        return fit_key(candidate, data)

    def fitted(self) -> dict:
        self._check_fitted("base_")
        return {"chosen": self.chosen_, "chosen_by": self.chosen_by_,
                "candidates": len(self.inner_), "inner": self.inner_,
                "base": self.base_.fitted()}

    # -- running: the fitted base --------------------------------------------------------

    def thresholds(self) -> np.ndarray:
        self._check_fitted("base_")
        return self.base_.thresholds()

    def pool_thresholds(self, pools: list[dict[str, int]]) -> np.ndarray | None:
        """The chosen base's (the choice itself kept)."""
        self._check_fitted("base_")
        return self.base_.pool_thresholds(pools)

    def probes(self) -> dict[str, float]:
        return self.base_.probes() if hasattr(self, "base_") else self._reference().probes()

    def reset(self) -> NestedSelection:
        self._check_fitted("base_")
        self.base_.reset()
        return self

    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        return self.base_.update(x, fresh)

    def snapshot(self) -> object | None:
        self._check_fitted("base_")
        return self.base_.snapshot()

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: object | None = None) -> tuple[np.ndarray, dict]:
        self._check_fitted("base_")
        if state is None:
            return self.base_.run(s, probes)
        return self.base_.run(s, probes, start=start, state=state)
