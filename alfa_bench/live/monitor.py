"""A fitted detector on a MAVLink link or log: messages in, decisions out.

:class:`Monitor` takes messages in time order (:meth:`Monitor.feed`), maps them to the
detector's signals (:mod:`.mavlink`) and holds each signal onto the detector's grid by
the data layer's zero-order hold (:func:`alfa_bench.data.hold`): a grid step's value is
the signal's last record at or before it, fresh when that record's value differs from
the record before the previous step's. The grid is :math:`k / f` on the source's clock
(``f`` the detector's rate) from the first step at which every signal has a record; a
step is decided once a message later than it arrives (no record for it can come after).
Each step feeds :meth:`~alfa_bench.methods.Detector.update`; a channel whose score
exceeds its threshold is an alarm (:class:`Decision`). A channel reading a sensor that
has not moved since arming is not scored (NaN) until it does, by the batch run's rule
(:class:`~alfa_bench.methods.UnmovedSensors`).

The clock (:func:`message_time`) is a log's timestamp (``clock="log"``, a ``.tlog``) or
the messages' own time fields (``clock="link"``): ``time_usec``, ``time_boot_ms``, a
message without one dated by the last ``SYSTEM_TIME`` or timed message before it. Times
are reported from :attr:`Monitor.origin_s`: on a log, the whole second before its first
message (a replayed ALFA flight's own clock, to the second); on a link, the autopilot's
boot.
"""

from __future__ import annotations

import logging
import math
import socket
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from alfa_bench.data import MAX_HOLD_S, SIGNALS, first_grid_step, hold
from alfa_bench.methods import Detector, UnmovedSensors

from . import mavlink

__all__ = ["REORDER_S", "Decision", "Monitor", "message_time", "watch"]

#: a message this much earlier than one taken is re-dated to it (a ``time_boot_ms``
#: after a ``time_usec`` of the same millisecond), not dropped, s
REORDER_S = 0.002

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Decision:
    """One grid step decided: its time (the source's clock), the scores and thresholds
    per channel, and the channels that alarm."""

    t: float
    scores: dict[str, float]
    thresholds: dict[str, float]
    alarms: tuple[str, ...]


@dataclass
class _Records:
    """One measured signal's records not yet behind the last grid step decided."""

    t: list[float] = field(default_factory=list)
    value: list[float] = field(default_factory=list)
    changed: list[bool] = field(default_factory=list)
    first: int = 0             # global index of t[0]
    source_of_first: int = 0   # global index of the change t[0]'s value came from
    last_value: float = math.nan
    count: int = 0

    def add(self, t: float, v: float) -> None:
        self.t.append(t)
        self.value.append(v)
        # a NaN is a change every time, as the data layer's `!=` counts it
        self.changed.append(self.count == 0 or not v == self.last_value)
        self.last_value = v
        self.count += 1

    def forget_before(self, t: float) -> None:
        """Drop the records before ``t``, the last one kept (while the grid waits)."""
        n = min(int(np.searchsorted(self.t, t)), len(self.t) - 1)
        if n > 0:
            self.at(self.t[n])

    def at(self, t_step: float) -> tuple[float, int, float]:
        """The value held at ``t_step``, the global index of its source and the time of
        the record held; then the records before it are dropped."""
        changed = np.array(self.changed)
        changed[0] = True       # its source is kept in source_of_first
        row, source = hold(np.array(self.t), changed, np.array([t_step]))
        row, source = int(row[0]), int(source[0])
        value, since = self.value[row], self.t[row]
        source = self.source_of_first if source == 0 else self.first + source
        if row:
            self.source_of_first = source
            del self.t[:row], self.value[:row], self.changed[:row]
            self.first += row
        return value, source, since


def message_time(msg, clock: str, state: dict) -> float:
    """The time of the pymavlink message ``msg``, s: its log timestamp
    (``clock="log"``), or its own time field (``"link"``; a message without one takes
    the last time seen, kept in ``state``)."""
    if clock == "log":
        return float(msg._timestamp)
    name = mavlink.TIMED.get(msg.get_type())
    if name == "time_usec":
        state["t"] = msg.time_usec * 1e-6
    elif name == "time_boot_ms":
        state["t"] = msg.time_boot_ms * 1e-3
    return state.get("t", math.nan)


class Monitor:
    """A fitted ``detector`` on a stream of MAVLink messages (module docstring).

    Parameters
    ----------
    detector : Detector
        Fitted (from a model file: :func:`alfa_bench.load_model`).
    allow_actuators : bool
        Run a detector that reads a signal ALFA's fault emulation writes (servo outputs,
        throttle); refused by default.
    on_decision : callable, optional
        Called with every :class:`Decision`.
    stale_s : float
        The longest a signal's value is held (the data layer's
        :data:`~alfa_bench.data.MAX_HOLD_S`, beyond which it refuses a flight): past it,
        the monitor re-arms.

    The input's state is named in the log when it changes (:attr:`state`): waiting for
    every signal, armed, a value out of the signal's physical bounds (dropped, the last
    plausible one held), a signal stale (re-arming), the clock gone back (re-arming). A
    message more than ``stale_s`` away from the last one taken is dropped unless the
    next confirms the jump; one earlier than the last taken is dropped (up to
    :data:`REORDER_S` earlier it is re-dated); :attr:`dropped` counts each kind.
    """

    def __init__(self, detector: Detector, allow_actuators: bool = False,
                 on_decision=None, stale_s: float = MAX_HOLD_S):
        names = detector.signals()
        actuators = [n for n in names if SIGNALS[n].kind == "actuator"]
        if actuators and not allow_actuators:
            raise ValueError(f"the model reads {actuators}, written by ALFA's fault "
                             "emulation, not measured: refused for a live link unless "
                             "allowed explicitly")
        self.detector = detector.reset()
        self.unmoved = UnmovedSensors(detector)
        self.names = tuple(names)
        self.measured = mavlink.fields_for(names)
        self.records = {n: _Records() for n in self.measured}
        self.rate_hz = float(detector.rate_hz)
        self.channels = detector.channels()
        self.thresholds = dict(zip(self.channels, map(float, detector.thresholds()),
                                   strict=True))
        self.on_decision = on_decision
        self.stale_s = stale_s
        self.next_step: int | None = None
        self.last_t = -math.inf
        self.jump_to: float | None = None
        self.state = "waiting for every signal"
        self.dropped: Counter = Counter()
        self.prev_source = {n: -1 for n in self.measured}
        self.steps = 0
        self.messages = 0
        self.first_alarm: Decision | None = None
        self.alarming: set[str] = set()
        self.origin_s: float | None = None
        #: the vehicle armed by its last HEARTBEAT (None: no HEARTBEAT read)
        self.vehicle_armed: bool | None = None

    def missing(self) -> list[str]:
        """The measured signals no message has given yet."""
        return [n for n, r in self.records.items() if not r.count]

    @property
    def armed(self) -> bool:
        """Whether every signal has a record: the grid has started."""
        return self.next_step is not None

    def feed(self, t: float, message: str, values: dict[str, float]) -> list[Decision]:
        """Take a message of type ``message`` at time ``t`` whose signals are ``values``
        (:func:`.mavlink.decode`): decide every grid step before ``t``, then keep its
        records. Returns the steps decided."""
        self.messages += 1
        if not math.isfinite(t):
            self.dropped["no time"] += 1
            return []
        if math.isfinite(self.last_t) and abs(t - self.last_t) > self.stale_s:
            # a jump is taken once the next message confirms it: a single wild stamp (a
            # log's unprotected timestamp, a corrupt field) is dropped
            if self.jump_to is None or abs(t - self.jump_to) > self.stale_s:
                self.jump_to = t
                self.dropped["time jump, not confirmed"] += 1
                return []
            if t < self.last_t:         # the source's clock started again
                self._rearm([], t, f"the clock went back {self.last_t - t:.1f} s")
                self.last_t = t
        self.jump_to = None
        if t < self.last_t - REORDER_S:
            self.dropped["out of order"] += 1
            self._set_state("out of order: messages earlier than one taken are dropped",
                            self.last_t)
            return []
        # a millisecond stamp after a microsecond one of the same instant
        t = max(t, self.last_t)
        decided = self._advance(t) if self.armed else []
        self.last_t = t
        plausible = True
        for name, v in values.items():
            if name not in self.records:
                continue
            lo, hi = SIGNALS[name].bounds or (-math.inf, math.inf)
            if not lo <= v <= hi:        # NaN too
                self.dropped[f"implausible {name}"] += 1
                self._set_state(f"implausible {name}: {v:.6g} {SIGNALS[name].unit}, "
                                "the last plausible value held", t)
                plausible = False
                continue
            self.records[name].add(t, v)
        if not self.armed:
            if all(r.count for r in self.records.values()):
                start = max(r.t[0] for r in self.records.values())
                self.next_step = first_grid_step(start, self.rate_hz)
            else:               # waiting: what is older than a hold cannot start the grid
                for r in self.records.values():
                    r.forget_before(t - self.stale_s)
        if self.armed and plausible:
            self._set_state("armed", t)
        return decided

    def _set_state(self, state: str, t: float) -> None:
        if state != self.state:
            log.warning("%s at t=%.2f s", state, t)
            self.state = state

    def _advance(self, t: float) -> list[Decision]:
        out = []
        while self.armed and self.next_step / self.rate_hz < t:
            decision = self._step(self.next_step / self.rate_hz)
            if decision is not None:
                out.append(decision)
                self.next_step += 1
        return out

    def _rearm(self, stale: list[str], t_step: float, why: str | None = None) -> None:
        """A signal held longer than ``stale_s`` (or a clock that started again): the
        detector starts again from its reset (its warm-up too) once every signal has a
        record after the gap."""
        why = why or f"stale: {', '.join(stale)} held over {self.stale_s:g} s"
        self._set_state(f"{why}; re-arming", t_step)
        self.detector.reset()
        self.unmoved = UnmovedSensors(self.detector)
        self.records = {n: _Records() for n in self.measured}
        self.prev_source = {n: -1 for n in self.measured}
        self.next_step = None

    def _step(self, t_step: float) -> Decision | None:
        held, fresh, stale = {}, {}, []
        for name, r in self.records.items():
            held[name], source, since = r.at(t_step)
            if t_step - since > self.stale_s:
                stale.append(name)
            fresh[name] = source != self.prev_source[name]
            self.prev_source[name] = source
        if stale:
            self._rearm(stale, t_step)
            return None
        x = np.array([held[mavlink.DIFFERENCES[n][0]] - held[mavlink.DIFFERENCES[n][1]]
                      if n in mavlink.DIFFERENCES else held[n] for n in self.names])
        f = np.array([fresh[mavlink.DIFFERENCES[n][0]] if n in mavlink.DIFFERENCES
                      else fresh[n] for n in self.names])
        score = np.array(self.detector.update(x, f), dtype=float)
        was = self.unmoved.unmoved()
        score[self.unmoved.blanked(x[None, :])[0]] = np.nan
        if self.unmoved.unmoved() != was:
            log.info("not scored while unmoved since arming: %s at t=%.2f s",
                        ", ".join(self.unmoved.unmoved()) or "none", t_step)
        alarm = self.detector.alarms(score[None, :])[0]
        decision = Decision(t_step, dict(zip(self.channels, map(float, score), strict=True)),
                            self.thresholds,
                            tuple(c for c, a in zip(self.channels, alarm, strict=True) if a))
        self.steps += 1
        if decision.alarms and self.first_alarm is None:
            self.first_alarm = decision
        for c in set(decision.alarms) - self.alarming:
            log.warning("alarm t=%.2f s channel=%s score=%.4g threshold=%.4g", t_step, c,
                        decision.scores[c], decision.thresholds[c])
        self.alarming = set(decision.alarms)
        if self.on_decision is not None:
            self.on_decision(decision)
        return decision


def _magic(path: str) -> bytes:
    with open(path, "rb") as f:
        return f.read(4)


def watch(source: str, monitor: Monitor, clock: str | None = None,
          stop=lambda: False) -> Monitor:
    """Feed ``monitor`` from ``source`` in pymavlink's connection syntax (a ``.tlog``
    file, ``udpin:0.0.0.0:14550``, ``tcp:host:port``, a serial device) until a file
    ends or ``stop()`` is true: the message types its signals need, from the system that
    sent the first of them. ``clock`` defaults to ``"log"`` for a file, else
    ``"link"``; a log's times are counted from the whole second before its first
    message (``monitor.origin_s``), so that its grid is the flight's. The autopilot's
    ``HEARTBEAT`` says whether the vehicle is armed (``monitor.vehicle_armed``).

    A PX4 ULog or an ArduPilot DataFlash log (``.bin``) is refused (ValueError): their
    messages are not MAVLink's."""
    from pymavlink import DFReader, mavutil

    is_file = Path(source).is_file()
    if not is_file and ":" not in source and not Path(source).exists():
        raise FileNotFoundError(f"{source}: no such log, device or link")
    if is_file and _magic(source) == b"ULog":
        raise ValueError(f"{source}: a PX4 ULog, not read: the monitor reads MAVLink, a "
                         "telemetry log (.tlog) or a link")
    clock = clock or ("log" if is_file else "link")
    conn = mavutil.mavlink_connection(source, robust_parsing=True, dialect="ardupilotmega")
    if isinstance(conn, DFReader.DFReader):
        conn.close()
        raise ValueError(f"{source}: an ArduPilot DataFlash log, not read: its messages "
                         "are not MAVLink's; the monitor reads a telemetry log (.tlog) "
                         "or a link")
    sock = getattr(conn, "port", None)
    if isinstance(sock, socket.socket) and sock.type == socket.SOCK_DGRAM:
        # a burst outruns a slow step: the kernel holds it rather than drop it
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 8 << 20)
    wanted = [*mavlink.messages_for(monitor.names), "SYSTEM_TIME", "HEARTBEAT"]
    state: dict = {}
    monitor.origin_s = None
    system = None
    try:
        while not stop():
            msg = conn.recv_match(type=wanted, blocking=not is_file, timeout=0.2)
            if msg is None:
                if is_file:
                    break
                continue
            kind = msg.get_type()
            # a ground station's or companion's heartbeat names no autopilot
            if kind == "HEARTBEAT" and msg.autopilot == mavutil.mavlink.MAV_AUTOPILOT_INVALID:
                continue
            # the autopilot's messages only: a ground station's SYSTEM_TIME is another clock
            system = msg.get_srcSystem() if system is None else system
            if msg.get_srcSystem() != system:
                monitor.dropped["another system"] += 1
                continue
            if kind == "HEARTBEAT":
                monitor.vehicle_armed = bool(
                    msg.base_mode & mavutil.mavlink.MAV_MODE_FLAG_SAFETY_ARMED)
                continue
            t = message_time(msg, clock, state)
            if not math.isfinite(t):
                continue
            if monitor.origin_s is None:
                monitor.origin_s = float(math.floor(t)) if clock == "log" else 0.0
            monitor.feed(t - monitor.origin_s, kind,
                         mavlink.decode(kind, lambda name, m=msg: getattr(m, name)))
    finally:
        conn.close()
    return monitor
