"""The streaming detector contract and the causal batch runner.

A detector is built from hyper-parameters only; :meth:`Detector.reset` creates its
learned state (attributes ending in ``_``); :meth:`Detector.update` consumes one
time step of the signals it asks for and returns the score of each channel for that
step. A channel alarms exactly when its score exceeds its threshold
(:meth:`Detector.thresholds`): :meth:`Detector.alarms` derives the alarms from the
scores, for every detector alike, so stored scores can be re-thresholded without
re-running the detector. A flight alarms when any channel alarms.
:meth:`Detector.probes` exposes the intermediates of the last step (prediction,
residual, ...) for inspection.

A run can be *forked*: :meth:`Detector.snapshot` copies the running state after the
first :math:`k` steps of a flight, and ``run(s, start=k, state=...)`` continues any
flight that shares those :math:`k` steps from it, as if it had been run from
:math:`t = 0`. A state belongs to the fit and hyper-parameters it was taken under
(:func:`fit_token`): continuing it under others raises :class:`StaleStateError`. The
injected sensor faults are their source flight, unchanged, up to the onset, so the
steps before it are run once per source and onset (:func:`forks`), not once per
injected flight. A detector whose :meth:`snapshot` is None is run from :math:`t = 0`
instead.

A *calibrated* detector also learns from fault-free data before it runs:
:meth:`Detector.fit` takes fault-free segments (whole fault-free flights and the
pre-fault parts of the others, never the flight to be scored) and sets its fitted
attributes (ending in ``_``, kept by :meth:`~Detector.reset`);
:meth:`~Detector.fitted` reports them for the detection record.

A *supervised* detector (``supervised = True``, and calibrated) learns from labelled
flights instead: its :meth:`~Detector.fit` receives :class:`Labelled` segments
(:func:`labelled_segments`), whole flights of the other groups with their onset and
fault class, so it may learn what a fault looks like. It says so: the tables'
calibration column reads ``supervised``. Neither kind ever sees a flight of the group
it scores (:func:`alfa_bench.analysis.held_out.check_held_out`).

A signal that is not measured on a flight (constant over all of it, like measured
airspeed from 2018-09-11 on) is never modelled: :func:`run_detector` does not score
the channels that score it, or any channel when a model input is dead, until the
sensor moves (causally, as the live monitor does: :mod:`.unmoved`), and
:func:`fault_free_segments` leaves such flights out of calibration. Both are logged
and recorded.

The least a detector writes is its ``__init__`` (storing its hyper-parameters),
:meth:`Detector.signals` and :meth:`Detector.update`: it then has one channel, named
for its class, scoring its first signal, and alarms above its ``threshold``
hyper-parameter. A calibrated one that budgets false alarms per flight takes its
thresholds from :class:`~.extremes.MaximaThresholds`. Data too short to fit raises
:class:`CalibrationError`, the one error the workflow turns into a calibration-failure
row.
"""

from __future__ import annotations

import copy
import functools
import hashlib
import inspect
import logging
import math
import types
from abc import ABC, abstractmethod
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from alfa_bench.data import AlfaDataError, Flight, Sampled, not_measured, parse_flight_name, sample

from .unmoved import UnmovedSensors

__all__ = ["DEFAULT_RATE_HZ", "FAMILIES", "CalibrationError", "Detector", "Fork", "Labelled",
           "NotFittedError", "PairDetector", "StaleStateError", "Trace", "clone",
           "continue_forks", "fault_free_segments", "fit_token", "fork_for", "forks",
           "free_part", "json_ready", "labelled_segments", "learned_state",
           "leave_one_date_out", "run_detector", "segment_digest", "source_digest",
           "training_segments"]

log = logging.getLogger(__name__)


#: the families of detectors the tables name, and ``other`` for one that says none
FAMILIES = ("model residuals", "parameter monitoring", "statistical test", "generic outlier",
            "supervised classifier", "reference", "other")

#: the grid rate of a detector that does not set its own, Hz: ALFA's attitude rows come
#: at about 20 Hz
DEFAULT_RATE_HZ = 20.0


class NotFittedError(RuntimeError):
    """A calibrated detector was run before :meth:`Detector.fit`."""


class CalibrationError(ValueError):
    """The data given to :meth:`Detector.fit` is too little or too short to fit: a fold
    the workflow reports as not calibrated (a failure row), or a nested candidate it
    leaves unscored. Any other error of a fit is a bug, and stops the run."""


class StaleStateError(RuntimeError):
    """A run was to continue from a state taken under another fit or other
    hyper-parameters than the detector now has."""


def learned_state(detector: Detector) -> dict:
    """The learned attributes of ``detector`` (names ending in ``_``), by name."""
    return {n: v for n, v in vars(detector).items()
            if n.endswith("_") and not n.startswith("_")}


def _feed(h, value, seen: set[int]) -> None:
    """Feed ``value`` to the hash ``h`` by value: arrays by their bytes, containers by
    their items, other objects by their attributes (``repr`` only for what has none)."""
    if isinstance(value, np.ndarray | np.generic):
        value = np.asarray(value)
        h.update(f"<{value.dtype.str}{value.shape}>".encode())
        if value.dtype.hasobject:
            for item in value.ravel():
                _feed(h, item, seen)
        else:
            h.update(np.ascontiguousarray(value).tobytes())
    elif value is None or isinstance(value, str | int | float | complex | bytes):
        h.update(f"{type(value).__name__}:{value!r};".encode())
    elif isinstance(value, dict):
        h.update(b"{")
        for k, v in value.items():
            _feed(h, k, seen)
            _feed(h, v, seen)
        h.update(b"}")
    elif isinstance(value, list | tuple | deque):
        h.update(f"{type(value).__name__}[".encode())
        for v in value:
            _feed(h, v, seen)
        h.update(b"]")
    elif isinstance(value, set | frozenset):
        _feed(h, sorted(value, key=repr), seen)
    elif isinstance(value, type) or (callable(value) and hasattr(value, "__qualname__")):
        # a class or a function: by its name, which the same code keeps across copies
        h.update(f"{getattr(value, '__module__', '')}.{value.__qualname__}".encode())
    elif id(value) in seen:
        h.update(b"<seen>")
    elif hasattr(value, "__dict__"):
        seen.add(id(value))
        h.update(f"{type(value).__module__}.{type(value).__qualname__}".encode())
        _feed(h, vars(value), seen)
    else:
        # an extension type (a scikit-learn tree): by what it pickles as
        seen.add(id(value))
        h.update(type(value).__qualname__.encode())
        try:
            reduced = value.__reduce_ex__(4)
        except (TypeError, ValueError):
            reduced = None
        if isinstance(reduced, tuple):
            _feed(h, list(reduced[1:3]), seen)
        else:
            h.update(repr(value).encode())


def _digest(*values) -> str:
    h = hashlib.blake2b(digest_size=16)
    for v in values:
        _feed(h, v, set())
    return h.hexdigest()


def _fit_state(detector: Detector) -> dict:
    return {n: v for n, v in learned_state(detector).items()
            if n not in ("fit_digest_", "fit_report_")}


def learned_digest(detector: Detector) -> str:
    """A digest, by value, of every attribute ``detector`` has learned (but the digest
    and report its fit leaves): its ``fit_digest_`` right after a fit."""
    return _digest(_fit_state(detector))


def fit_token(detector: Detector) -> str:
    """What a running state belongs to: a digest of the detector's hyper-parameters and
    of every attribute its last :meth:`~Detector.fit` (or
    :meth:`~Detector.rethreshold`) left, by value (``fit_digest_``, set when the fit
    returns)."""
    return _digest(detector.get_params(), getattr(detector, "fit_digest_", None))


def json_ready(value):
    """``value`` as JSON-ready values: arrays as lists, non-finite floats as None,
    mapping keys as strings, a detector as its :meth:`~Detector.fitted`, another object
    as its attributes (its ``repr`` where it has none)."""
    if isinstance(value, np.ndarray | np.generic):
        return json_ready(np.asarray(value).tolist())
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if value is None or isinstance(value, str | int | bool):
        return value
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, list | tuple | deque | set | frozenset):
        return [json_ready(v) for v in value]
    if isinstance(value, Detector):
        return value.fitted()
    if hasattr(value, "__dict__"):
        return json_ready(vars(value))
    return repr(value)


@functools.cache
def init_parameters(cls: type) -> types.MappingProxyType:
    """``cls.__init__``'s parameters by name, read once per class: every detector built
    reads them, and a nested selection builds its base each time it is asked its
    layout."""
    return inspect.signature(cls.__init__).parameters


@functools.cache
def source_digest(cls: type, package: bool = False) -> str:
    """A digest of the code of ``cls`` and of its bases outside alfa-bench (with
    ``package``, alfa-bench's own too): the source where it can be read, else its
    compiled code (a class typed into a notebook or run as ``__main__``:
    :func:`_compiled`), the same in every process. Read once per class (finding a
    class's source parses its module): a class object runs the code it was made
    from, whatever its file says later."""
    skipped = ("builtins", "abc") if package else ("alfa_bench", "builtins", "abc")
    h = hashlib.blake2b(digest_size=16)
    for c in cls.__mro__:
        if c.__module__.split(".")[0] in skipped:
            continue
        try:
            h.update(inspect.getsource(c).encode())
        except (OSError, TypeError):
            h.update(_compiled(c))
    return h.hexdigest()


def _compiled(cls: type) -> bytes:
    """What ``cls`` runs, without its source: each function's code (a sealed fit's own,
    :func:`_sealed`; a property's accessors) and each attribute of plain data, by
    name."""
    out = []
    for name, value in sorted(vars(cls).items()):
        value = getattr(value, "__func__", value)            # classmethod, staticmethod
        functions = ([value.fget, value.fset, value.fdel] if isinstance(value, property)
                     else [value])
        codes = [getattr(getattr(f, "__wrapped__", f), "__code__", None) for f in functions]
        if any(c is not None for c in codes):
            out += [name.encode(), *(_stable(c) for c in codes)]
        elif _plain_constant(value):
            out += [name.encode(), _stable(value)]
    return b"\0".join(out)


def _plain_constant(value) -> bool:
    if isinstance(value, tuple | frozenset):
        return all(map(_plain_constant, value))
    return value is None or isinstance(value, str | bytes | int | float | complex)


def _stable(value) -> bytes:
    """``value`` (a code object, or one of its constants) as bytes that are the same in
    every process: a nested function's code by its content, not by its ``repr`` (which
    holds its address), and a set's items in sorted order (not the order of the
    process's string hashes)."""
    if isinstance(value, types.CodeType):
        fields = (value.co_argcount, value.co_posonlyargcount, value.co_kwonlyargcount,
                  value.co_flags, value.co_names, value.co_varnames, value.co_freevars,
                  value.co_cellvars)
        return b"code(" + b"\0".join([value.co_code, value.co_exceptiontable,
                                       repr(fields).encode(),
                                       *map(_stable, value.co_consts)]) + b")"
    if isinstance(value, frozenset | set):
        return b"set(" + b"\0".join(sorted(map(_stable, value))) + b")"
    if isinstance(value, tuple):
        return b"tuple(" + b"\0".join(map(_stable, value)) + b")"
    return f"{type(value).__name__}:{value!r}".encode()


def clone(detector: Detector) -> Detector:
    """A new, unfitted detector with a copy of ``detector``'s hyper-parameters."""
    return type(detector)(**copy.deepcopy(detector.get_params()))


#: ids of the detectors inside a sealed fit, so that a fit calling its parent's fit
#: starts from nothing once and is sealed once it returns
_FITTING: set[int] = set()


def _sealed(method, forget: bool):
    """``method`` (a :meth:`~Detector.fit` or :meth:`~Detector.rethreshold`) made safe by
    construction: a fit first forgets every learned attribute (``forget``), so that a
    refit is a fresh fit; on return, ``fit_digest_`` digests by value what it left, so
    that no state taken under another fit can be continued (:func:`fit_token`)."""
    @functools.wraps(method)
    def sealed(self, *args, **kwargs):
        if id(self) in _FITTING:
            return method(self, *args, **kwargs)
        _FITTING.add(id(self))
        try:
            if forget:
                for name in learned_state(self):
                    delattr(self, name)
            out = method(self, *args, **kwargs)
        finally:
            _FITTING.discard(id(self))
        if self.calibrated and type(self).fitted is Detector.fitted:
            self.fit_report_ = json_ready(_fit_state(self))
        self.fit_digest_ = learned_digest(self)
        return out

    sealed.seals_the_fit = True
    return sealed


@dataclass(frozen=True)
class _Snapshot:
    """The default :meth:`Detector.snapshot`: the attributes, and the fit they hold."""

    token: str
    attributes: dict


class Detector(ABC):
    """Base class of every registered detector.

    Subclasses store their ``__init__`` arguments unchanged under the same names
    and nothing else, so that :meth:`get_params` can report them. Only
    :meth:`signals` and :meth:`update` must be written; the other members have
    defaults for a one-channel detector with a ``threshold`` hyper-parameter.
    """

    #: grid rate of the samples :meth:`update` expects, Hz
    rate_hz: float = DEFAULT_RATE_HZ
    #: whether :meth:`fit` must see fault-free data before the detector can run
    calibrated: bool = False
    #: whether :meth:`fit` learns from labelled flights (:class:`Labelled` segments)
    #: rather than from fault-free data alone; only with ``calibrated``
    supervised: bool = False
    #: whether each output depends on the data up to then only; a detector that is
    #: not may serve only as a reference row (``role: reference`` in the config)
    causal: bool = True
    #: hyper-parameters that set only the thresholds, from what :meth:`fit` learned:
    #: whatever their values, the scores and all else it learns are the same, and
    #: :meth:`rethreshold` sets the thresholds for new values without fitting again
    threshold_params: tuple[str, ...] = ()
    #: the family the tables group it in, one of :data:`FAMILIES` (a detector that says
    #: none is ``other``)
    family: str = "other"

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        for name in ("fit", "rethreshold"):
            method = getattr(cls, name)
            if not getattr(method, "seals_the_fit", False):
                setattr(cls, name, _sealed(method, forget=name == "fit"))

    @classmethod
    def param_names(cls) -> list[str]:
        """The hyper-parameters' names: those of ``__init__`` (none without one)."""
        if cls.__init__ is object.__init__:
            return []
        return [n for n, p in init_parameters(cls).items()
                if n != "self" and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]

    def get_params(self) -> dict:
        """Hyper-parameters by name, as passed to ``__init__``."""
        return {n: getattr(self, n) for n in self.param_names()}

    def check_params(self) -> None:  # noqa: B027 (a hook: most detectors name nothing)
        """Resolve what the hyper-parameters name outside the package (a library's model
        by its name), raising :class:`ValueError` where one does not resolve, saying what
        to do. The workflow's dry run calls it for every configured run, so that a run
        fails there, not in its job. Nothing to resolve by default."""

    def warm(self) -> None:  # noqa: B027 (a hook: most detectors have nothing to warm)
        """Do once, in a process that forks jobs (the workflow's fork server), what the
        first fit of every process would do again: a library's just-in-time compilation.
        It learns nothing (the detector stays as it was built) and moves no random
        state, so a job forked after it computes what it computes alone. Nothing by
        default."""

    @abstractmethod
    def signals(self) -> tuple[str, ...]:
        """Names (see :data:`alfa_bench.data.SIGNALS`) of the input columns."""

    def channels(self) -> tuple[str, ...]:
        """Names of the score channels; by default one, named for the class."""
        return (type(self).__name__.lower(),)

    def channel_outputs(self) -> tuple[str, ...]:
        """Per channel, the measured signal whose behaviour it scores: what the
        channel isolates when it alarms first. By default, for one channel, the first
        of :meth:`signals`."""
        if len(self.channels()) != 1:
            raise NotImplementedError(f"{type(self).__name__} has several channels: say "
                                      "which signal each scores in channel_outputs()")
        return self.signals()[:1]

    def fit(self, segments: list[Sampled] | list[Labelled]) -> Detector:
        """Learn from fault-free ``segments`` (sampled with :meth:`signals` at
        :attr:`rate_hz`), or from :class:`Labelled` ones if :attr:`supervised`; return
        self. Uncalibrated detectors learn nothing here.

        Every subclass's fit is sealed by the base class: it starts from no learned
        attribute (a refit is a fresh fit), and what it leaves is digested by value
        into ``fit_digest_`` (:func:`fit_token`)."""
        return self

    def fitted(self) -> dict:
        """What :meth:`fit` learned, as JSON-ready values (:func:`json_ready`): by
        default every learned attribute as the fit left it; empty if uncalibrated."""
        if not self.calibrated:
            return {}
        self._check_fitted("fit_report_")
        return self.fit_report_

    def _check_fitted(self, attribute: str) -> None:
        if not hasattr(self, attribute):
            raise NotFittedError(f"{type(self).__name__} is calibrated: call fit() on "
                                 "fault-free segments before running it")

    def rethreshold(self) -> Detector:
        """Set the thresholds again from what :meth:`fit` learned, for the current
        values of :attr:`threshold_params`; return self. Raise
        :class:`CalibrationError` where :meth:`fit` would. Only a detector that
        declares ``threshold_params`` has it."""
        raise NotImplementedError(f"{type(self).__name__} declares no threshold_params")

    def thresholds(self) -> np.ndarray:
        """Per channel, the threshold :math:`\\gamma_c > 0` in score units: channel
        :math:`c` alarms when :math:`s_c(k) > \\gamma_c`. By default the
        ``threshold`` hyper-parameter, for every channel."""
        if "threshold" not in self.param_names():
            raise NotImplementedError(
                f"{type(self).__name__} has no `threshold` hyper-parameter and no "
                "thresholds() of its own, so its channels cannot alarm: add a `threshold` "
                "argument to __init__ (stored as self.threshold), or define thresholds() "
                "returning one positive threshold per channel")
        return np.full(len(self.channels()), float(self.threshold))

    def probes(self) -> dict[str, float]:
        """Intermediates of the last :meth:`update` by name (``"<channel>/prediction"``,
        ``"<channel>/residual"``, ...; NaN where not computed). Names are fixed after
        :meth:`reset`. None by default."""
        return {}

    def reset(self) -> Detector:
        """Forget everything learned while running (not what :meth:`fit` learned);
        return self. A detector without running state need not define it."""
        return self

    def pool_thresholds(self, pools: list[dict[str, int]]) -> np.ndarray | None:
        """The thresholds :meth:`fit` would have set had its calibration flights been
        drawn as each of ``pools`` says (flight -> times drawn, a bootstrap), all else
        it learned kept: shape (pools, channels). None where the thresholds cannot be
        set again without fitting the model again (the default)."""
        return None

    def alarms(self, score: np.ndarray) -> np.ndarray:
        """Alarms of scores of shape (..., c): :math:`s_c(k) > \\gamma_c`; a NaN score
        (a channel not armed) never alarms."""
        with np.errstate(invalid="ignore"):
            return np.asarray(score) > self.thresholds()

    def snapshot(self) -> object | None:
        """A copy of the running state after the last :meth:`run` or :meth:`update`,
        for ``run(s, start=k, state=...)`` to continue from; None if the detector
        cannot continue from a state (a forked run then runs from :math:`t = 0`).

        By default a copy of the attributes where :meth:`run` is this class's, which
        steps :meth:`update`, with the :func:`fit_token` they were taken under, and
        None where a subclass overrides :meth:`run`: its batch form must say itself
        how it continues (and the contract test checks that it does so exactly). An
        override returns the running state only."""
        if type(self).run is not Detector.run:
            return None
        return _Snapshot(fit_token(self), copy.deepcopy(vars(self)))

    def run(self, s: Sampled, probes: bool = False, start: int = 0,
            state: object | None = None) -> tuple[np.ndarray, dict]:
        """:meth:`reset`, then :meth:`update` over every step of ``s``: scores, shape
        (n, c), and with ``probes`` the :meth:`probes` of every step. Detectors may
        override it with a batch form; it must give the same scores to rounding (the
        contract test checks).

        With ``state``, a :meth:`snapshot` taken after running the first ``start``
        steps of ``s``: no reset; the run continues from it over steps ``start:``, and
        returns theirs only, shape (n - start, c). A state taken under another fit or
        other hyper-parameters raises :class:`StaleStateError`."""
        if state is None:
            self.reset()
            start = 0
        else:
            if state.token != fit_token(self):
                raise StaleStateError(f"{type(self).__name__}: the state to continue from "
                                      "was taken under another fit or other parameters")
            self.__dict__.update(copy.deepcopy(state.attributes))
        n, c = s.t.size - start, len(self.channels())
        score = np.empty((n, c))
        names = list(self.probes()) if probes else []
        kept = np.full((n, len(names)), np.nan)
        for k in range(n):
            try:
                out = self.update(s.x[start + k], s.fresh[start + k])
                if out is None:     # numpy would store it as NaN: a score never computed
                    raise ValueError("update() returned None")
                score[k] = out
            except ValueError as e:
                raise self._wrong_scores(s.x[start + k], s.fresh[start + k]) or e from e
            if names:
                kept[k] = list(self.probes().values())
        return score, {name: kept[:, i] for i, name in enumerate(names)}

    def run_many(self, items: list[tuple[Sampled, int, object]], probes: bool = False
                 ) -> list[tuple[np.ndarray, dict]]:
        """:meth:`run` of each ``(s, start, state)``: the continuations of many flights
        from their forks (:func:`continue_forks`). One :meth:`run` each by default; a
        detector whose model costs more a call than a row overrides it to score them
        all in one call (the contract test checks it gives each run's scores)."""
        return [self.run(s, probes, start, state) for s, start, state in items]

    def _wrong_scores(self, x: np.ndarray, fresh: np.ndarray) -> ValueError | None:
        """Where :meth:`update` returns other than one score per channel, the error that
        says so (the step is taken again on a copy); None where it does not."""
        raw = copy.deepcopy(self).update(x, fresh)
        channels = self.channels()
        if raw is None:
            return ValueError(f"{type(self).__name__}.update() returned None for "
                              f"{len(channels)} channel(s) {list(channels)}: return one "
                              "score per channel, an array of that length (NaN where a "
                              "score is not computed yet)")
        out = np.asarray(raw)
        if out.shape == (len(channels),):
            return None
        return ValueError(f"{type(self).__name__}.update() returned {out.size} value(s) of "
                          f"shape {out.shape} ({np.array2string(out, threshold=8)}) for "
                          f"{len(channels)} channel(s) {list(channels)}: return one score "
                          "per channel, or name the channels in channels()")

    @abstractmethod
    def update(self, x: np.ndarray, fresh: np.ndarray) -> np.ndarray:
        """Consume one time step.

        Parameters
        ----------
        x : ndarray, shape (m,)
            Values of :meth:`signals` at this step.
        fresh : ndarray of bool, shape (m,)
            Whether each value is a new measurement (see :func:`alfa_bench.data.sample`).

        Returns
        -------
        score : ndarray, shape (c,)
            Per channel; NaN while the channel is not yet armed. Its alarms are
            :meth:`alarms` of it.
        """


class PairDetector(Detector):
    """A detector with one score channel per input/output pair of ``self.pairs``
    (``{"name", "input", "output"}``): the channel is named for the pair and scores its
    output."""

    pairs: tuple

    def signals(self) -> tuple[str, ...]:
        """The pairs' signals, each once, in order of first use."""
        return tuple(dict.fromkeys(s for p in self.pairs for s in (p["input"], p["output"])))

    def channels(self) -> tuple[str, ...]:
        return tuple(p["name"] for p in self.pairs)

    def channel_outputs(self) -> tuple[str, ...]:
        return tuple(p["output"] for p in self.pairs)


@dataclass(frozen=True)
class Labelled:
    """A whole flight for a supervised :meth:`Detector.fit`: its samples and its label.

    Attributes
    ----------
    sampled : Sampled
        The flight, sampled as the detector reads it.
    onset_s : float or None
        Fault onset on the flight clock; None for a fault-free flight.
    fault_class : str
        ``none`` for a fault-free flight.
    emergency_trajectory : bool
        The flight switches to an emergency trajectory at onset: its commands carry
        the label from then on.
    """

    sampled: Sampled
    onset_s: float | None
    fault_class: str
    emergency_trajectory: bool = False

    @property
    def flight(self) -> str:
        return self.sampled.flight

    @property
    def t(self) -> np.ndarray:
        return self.sampled.t


@dataclass(frozen=True)
class Trace:
    """A detector's output over a flight, one row per grid step.

    Attributes
    ----------
    t : ndarray, shape (n,)
    score, alarm : ndarray, shape (n, c)
    channels : tuple of str
    threshold : ndarray, shape (c,)
    probes : dict of str to ndarray, shape (n,)
        :meth:`Detector.probes` per step, when asked for.
    skipped : dict of str to str
        Channels skipped on this flight (score NaN, never alarming), and why.
    """

    t: np.ndarray
    score: np.ndarray
    alarm: np.ndarray
    channels: tuple[str, ...]
    threshold: np.ndarray
    probes: dict = field(default_factory=dict)
    skipped: dict = field(default_factory=dict)

    @property
    def any_alarm(self) -> np.ndarray:
        return self.alarm.any(axis=1)

    def first_alarm_s(self, channel: int | None = None) -> float | None:
        """Time of the first alarm of ``channel`` (of any channel if None)."""
        a = self.any_alarm if channel is None else self.alarm[:, channel]
        return float(self.t[np.argmax(a)]) if a.any() else None

    def armed_s(self, channel: int) -> float | None:
        """Time of the first finite score of ``channel``: when it began to judge."""
        ok = np.isfinite(self.score[:, channel])
        return float(self.t[np.argmax(ok)]) if ok.any() else None

    def alarm_intervals(self) -> list[tuple[float, float]]:
        """Maximal runs of grid steps with an alarm, as (first, last) times."""
        a = self.any_alarm.astype(np.int8)
        edges = np.flatnonzero(np.diff(np.r_[0, a, 0]))
        return [(float(self.t[s]), float(self.t[e - 1])) for s, e in edges.reshape(-1, 2)]


@dataclass(frozen=True)
class Fork:
    """A detector's run over the first steps of a flight, for the flights that share
    them to continue from (:func:`forks`, :func:`run_detector`).

    Attributes
    ----------
    sampled : Sampled
        The steps run.
    state : object
        :meth:`Detector.snapshot` after them.
    score : ndarray, shape (k, c)
    probes : dict of str to ndarray, shape (k,)
        Empty unless the run kept them.
    kept_probes : bool
        Whether the run kept the probes.
    token : str
        The :func:`fit_token` of the detector that ran them.
    """

    sampled: Sampled
    state: object
    score: np.ndarray
    probes: dict
    kept_probes: bool
    token: str

    def shared_by(self, s: Sampled, probes: bool) -> bool:
        """Whether ``s`` begins with exactly these steps (times, values, freshness), and
        the fork kept the probes a run asks for."""
        k = self.sampled.t.size
        return (s.t.size >= k and (self.kept_probes or not probes)
                and np.array_equal(s.t[:k], self.sampled.t)
                and np.array_equal(s.x[:k], self.sampled.x, equal_nan=True)
                and np.array_equal(s.fresh[:k], self.sampled.fresh))

    def check(self, detector: Detector) -> None:
        """Raise :class:`StaleStateError` unless ``detector`` is fitted and configured as
        the one that ran these steps."""
        if fit_token(detector) != self.token:
            raise StaleStateError(f"{type(detector).__name__}: the fork was run under "
                                  "another fit or other parameters; fork again")

    def continued(self, detector: Detector, s: Sampled, probes: bool
                  ) -> tuple[np.ndarray, dict]:
        """``detector``'s scores and probes over ``s`` (a flight :meth:`shared_by`
        accepts), these steps' included, running only the steps after them. A
        detector fitted or configured otherwise than the one that ran them raises
        :class:`StaleStateError`."""
        self.check(detector)
        more, more_kept = detector.run(s, probes, start=self.sampled.t.size,
                                       state=self.state)
        return (np.vstack([self.score, more]),
                {n: np.concatenate([self.probes[n], v]) for n, v in more_kept.items()})


def forks(detector: Detector, flight: Flight, times_s, probes: bool = False
          ) -> dict[float, Fork]:
    """``detector`` run over ``flight`` up to each of ``times_s`` (its grid steps before
    each), each run continuing the one before: a :class:`Fork` per time. Empty when the
    detector cannot fork (:meth:`Detector.snapshot` is None)."""
    s = sample(flight, detector.signals(), detector.rate_hz)
    out, last = {}, None
    for t_s in sorted(set(times_s)):
        head = s.before(t_s)
        score, kept = (detector.run(head, probes) if last is None
                       else last.continued(detector, head, probes))
        state = detector.snapshot()
        if state is None:
            return {}
        out[t_s] = last = Fork(head, state, score, kept, probes, fit_token(detector))
    return out


def fork_for(forked: dict[float, Fork], onset_s: float | None) -> Fork | None:
    """Of ``forked`` (:func:`forks`), the fork a flight with its onset at ``onset_s``
    continues from: the latest at or before the onset; None if there is none."""
    at = max((t for t in forked if onset_s is not None and t <= onset_s), default=None)
    return forked.get(at)


def continue_forks(detector: Detector, flights: list[Flight], forked: dict[float, Fork]
                   ) -> dict[str, tuple[Sampled, np.ndarray, dict]]:
    """Each of ``flights`` that shares its fork's steps (:func:`fork_for`), sampled and
    scored from its fork, all in one :meth:`Detector.run_many` call: flight -> (its
    samples, its scores, no probes). A flight that cannot be sampled or shares no
    fork is left out, for :func:`run_detector` to run (or fail) on its own."""
    if not forked:                        # a detector that cannot fork: nothing to batch
        return {}
    todo = []
    for flight in flights:
        fork = fork_for(forked, flight.fault.onset_s if flight.fault else None)
        try:
            s = sample(flight, detector.signals(), detector.rate_hz)
        except AlfaDataError:
            continue
        if fork is not None and fork.shared_by(s, probes=False):
            fork.check(detector)
            todo.append((flight.id, s, fork))
    if not todo:
        return {}
    done = detector.run_many([(s, fork.sampled.t.size, fork.state) for _, s, fork in todo])
    return {name: (s, np.vstack([fork.score, more]), {})
            for (name, s, fork), (more, _) in zip(todo, done, strict=True)}


def run_detector(detector: Detector, flight: Flight, probes: bool = False,
                 fork: Fork | None = None,
                 continued: tuple[Sampled, np.ndarray, dict] | None = None) -> Trace:
    """Run ``detector`` causally over ``flight``, from a fresh state; with ``probes``,
    keep :meth:`Detector.probes` of every step. Channels on signals the flight does not
    measure are skipped: a channel is not scored while a sensor it reads has not moved
    since the first step, as the live monitor does (:class:`~.unmoved.UnmovedSensors`).

    With ``fork``, a flight that begins with the fork's steps continues from its state
    instead: the same trace, without running those steps again. One that does not (or
    a fork without the probes asked for) runs from a fresh state. With ``continued``
    (:func:`continue_forks` of this flight), its scores are already computed."""
    # first: an unfitted calibrated detector stops here, on NotFittedError
    threshold = np.asarray(detector.thresholds(), dtype=float)
    if continued is not None:
        s, score, kept = continued
    else:
        s = sample(flight, detector.signals(), detector.rate_hz)
        if fork is not None and fork.shared_by(s, probes):
            score, kept = fork.continued(detector, s, probes)
        else:
            score, kept = detector.run(s, probes)
    unmoved = UnmovedSensors(detector)
    blanked = unmoved.blanked(s.x)
    score[blanked] = np.nan
    skipped = unmoved.skipped()
    if skipped:
        log.info("%s: skipped %s", flight.id, skipped)
    for ch in np.flatnonzero(blanked.any(axis=0) & ~blanked.all(axis=0)):
        log.info("%s: %s not scored until %.2f s, a sensor it reads unmoved until then",
                 flight.id, detector.channels()[ch], s.t[np.argmin(blanked[:, ch])])
    return Trace(t=s.t, score=score, alarm=detector.alarms(score), channels=detector.channels(),
                 threshold=threshold, probes=kept, skipped=skipped)


def fault_free_segments(detector: Detector, flights: list[Flight],
                        margin_s: float) -> list[Sampled]:
    """The fault-free data of ``flights``, sampled as ``detector`` reads it.

    A fault-free flight gives all of itself, a faulty one its grid steps before
    ``onset - margin_s`` (the onset is known only to the ground truth's period). A
    flight without ground truth cannot tell its fault-free part and is refused. A
    flight that does not measure one of the detector's signals gives nothing (its
    constant would be modelled as data); it is logged.
    """
    segments = []
    for flight in flights:
        if flight.fault is None:
            raise ValueError(f"flight {flight.id} has no ground truth: its fault-free part "
                             "is unknown, so it cannot calibrate")
        dead = not_measured(flight, detector.signals())
        if dead:
            log.info("%s left out of calibration: %s not measured", flight.id, list(dead))
            continue
        s = sample(flight, detector.signals(), detector.rate_hz)
        if flight.fault.onset_s is not None:
            s = s.before(flight.fault.onset_s - margin_s)
        if s.t.size:
            segments.append(s)
    return segments


def labelled_segments(detector: Detector, flights: list[Flight]) -> list[Labelled]:
    """The whole of each of ``flights`` with its label, for a supervised ``detector``.
    As for :func:`fault_free_segments`, a flight without ground truth is refused and
    one that does not measure a signal of the detector gives nothing (logged)."""
    segments = []
    for flight in flights:
        if flight.fault is None:
            raise ValueError(f"flight {flight.id} has no ground truth, so it cannot train")
        dead = not_measured(flight, detector.signals())
        if dead:
            log.info("%s left out of training: %s not measured", flight.id, list(dead))
            continue
        segments.append(Labelled(sample(flight, detector.signals(), detector.rate_hz),
                                 flight.fault.onset_s, flight.fault.fault_class,
                                 flight.emergency_trajectory))
    return segments


def free_part(segment: Labelled, margin_s: float) -> Sampled:
    """The fault-free part of a labelled ``segment``, as :func:`fault_free_segments`
    cuts a flight: all of it if fault-free, else its steps before ``onset - margin_s``
    (possibly none)."""
    if segment.onset_s is None:
        return segment.sampled
    return segment.sampled.before(segment.onset_s - margin_s)


def segment_digest(s: Sampled | Labelled) -> bytes:
    """What identifies a segment's data: its flight, times, values and freshness, and a
    labelled one's label (a key under which a fit on the same data is kept)."""
    if isinstance(s, Labelled):
        label = (s.onset_s, s.fault_class, s.emergency_trajectory)
        return hashlib.sha256(segment_digest(s.sampled) + repr(label).encode()).digest()[:16]
    # SHA-256, not BLAKE2: a nested selection digests its training data for each fit it
    # asks for, and SHA-256 runs on the CPU's own instructions (2.9 times as fast on
    # the machine of BENCHMARKS.md)
    h = hashlib.sha256(s.flight.encode())
    for a in (s.t, s.x, s.fresh):
        h.update(np.ascontiguousarray(a).data)
    return h.digest()[:16]


def leave_one_date_out(segments: list) -> list[tuple[str, list, list]]:
    """The folds of an out-of-sample calibration: per date of ``segments`` (anything with
    a ``flight``: :class:`~alfa_bench.data.Sampled`, :class:`Labelled`), in date order,
    the date, the segments of every other date, and that date's. A model fitted on a
    fold's first list has seen no flight of its date."""
    dates = [str(parse_flight_name(s.flight)["date"]) for s in segments]
    return [(d, [s for s, sd in zip(segments, dates, strict=True) if sd != d],
             [s for s, sd in zip(segments, dates, strict=True) if sd == d])
            for d in sorted(set(dates))]


def training_segments(detector: Detector, flights: list[Flight],
                      margin_s: float) -> list[Sampled] | list[Labelled]:
    """What ``detector``'s :meth:`~Detector.fit` takes from ``flights``: their
    :func:`labelled_segments` if it is supervised, else their
    :func:`fault_free_segments`."""
    if detector.supervised:
        return labelled_segments(detector, flights)
    return fault_free_segments(detector, flights, margin_s)
