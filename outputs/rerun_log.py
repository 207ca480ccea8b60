"""The rerun recording of a flight: signals, every method's scores and intermediates.

The workflow writes it in parts, one file each, so that a changed run rewrites only its
own: the flight's (:func:`write_flight_part`: signals, fault, properties, layout),
``results/rerun/_flight/<flight>.rrd``, and each run's (:func:`write_run_part`),
``results/rerun/<method>/<flight>.rrd``. The parts of a flight share its recording id,
the flight's name, so the viewer opens them as one recording:
``rerun results/rerun/*/<flight>.rrd``. :func:`write_rerun_log` writes the whole
recording to one file. Everything is on the ``flight_time`` timeline (seconds on the
flight clock) and no wall-clock time is logged, so the same inputs give the same
entities, times and values (rerun's own row and chunk ids are time-based, so the bytes
differ between writes).

Entities
--------
``signals/<group>/<signal>``
    The raw input/output signals of every method, at their topics' record times
    (groups: attitude, attitude_error, rates, servos, airspeed).
``methods/<method>/scores/<k>``, ``methods/<method>/scores/threshold``
    The channels' scores, and their thresholds.
``methods/<method>/probes/<k>``
    The method's intermediates: prediction, residual (innovation), parameter change.
    Series defined at the same steps share one entity ``<k>`` (0, 1, ...), a scalar
    each, named in the legend: a row then stores its time and row id once for all of
    them, which halves the recording.
``overview/<method>``
    :math:`\\max_c s_c/\\gamma_c`: above 1 the method alarms.
``events``
    Fault onset and end, and the start of every alarm of every method.
Recording properties: ``flight`` (fault class, onset, end, date, label and the
code version that wrote the file), in the flight's part, and ``provenance`` (as JSON,
:func:`~.provenance.read_provenance` reads it back): each file carries its own.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from alfa_bench.analysis.provenance import code_version
from alfa_bench.analysis.sweep import ratio
from alfa_bench.data import SIGNALS, AlfaDataError, Flight, series
from alfa_bench.methods import Trace

__all__ = ["TIMELINE", "blueprint", "signal_group", "write_flight_part", "write_rerun_log",
           "write_run_part"]

log = logging.getLogger(__name__)

TIMELINE = "flight_time"
_APPLICATION = "alfa-bench"
_GROUPS = ("attitude", "attitude_error", "rates", "specific_force", "servos", "airspeed",
           "airspeed_error", "altitude")
_RED = (220, 40, 40)


def signal_group(name: str) -> str:
    """The view a signal is drawn in."""
    sig = SIGNALS[name]
    if sig.kind == "actuator":
        return "servos"      # the outputs the fault emulation writes, throttle included
    if sig.unit == "deg":
        return "attitude_error" if sig.minus else "attitude"
    # the autopilot's airspeed error is logged in cm/s: a view of its own, not m/s's
    return {"rad/s": "rates", "m/s^2": "specific_force", "m/s": "airspeed",
            "cm/s": "airspeed_error", "m": "altitude"}[sig.unit]


def blueprint(methods: list[str], groups: list[str], title: str = "",
              fault_span_s: tuple[float, float] | None = None) -> rrb.Blueprint:
    """Signals on top, all methods' score/threshold with the event log in the middle,
    one tab per method with its scores and intermediates below.

    Every plot shows the whole flight whatever the time cursor does (an infinite
    visible time range and x axis), and view titles carry ``title`` (the flight and its fault).
    Playback starts paused; with ``fault_span_s`` (onset, end) the time panel opens
    with the fault's span selected, so the story of the recording is in view."""
    ever = rrb.TimeRangeBoundary.infinite()
    whole = rrb.VisibleTimeRange(TIMELINE, start=ever, end=ever)
    # the x axis too: left to itself it follows the cursor, 30 s either side of it
    axis = rrb.TimeAxis(view_range=rrb.TimeRange(start=ever, end=ever))
    suffix = f" — {title}" if title else ""

    def plot(origin, name, **kw):
        return rrb.TimeSeriesView(origin=origin, name=name, time_ranges=whole, axis_x=axis,
                                  **kw)

    signals = rrb.Horizontal(*[plot(f"/signals/{g}", g + suffix) for g in groups])
    overview = rrb.Horizontal(
        plot("/overview", "score / threshold (alarm above 1; bar on top: the fault)" + suffix,
             axis_y=rrb.ScalarAxis(range=(0.0, 3.0))),
        rrb.TextLogView(origin="/events", name="events" + suffix),
        column_shares=[3, 2])
    tabs = rrb.Tabs(*[rrb.Horizontal(
        plot(f"/methods/{m}/scores", f"{m}: scores, thresholds"),
        plot(f"/methods/{m}/probes", f"{m}: intermediates"),
        name=m) for m in methods])
    selection = (None if fault_span_s is None else rrb.components.AbsoluteTimeRange(
        *(round(s * 1e9) for s in fault_span_s)))
    return rrb.Blueprint(
        rrb.Vertical(signals, overview, tabs, row_shares=[2, 2, 3]),
        rrb.TimePanel(state="expanded", timeline=TIMELINE, play_state="paused",
                      time_selection=selection),
        rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"))


def _series(rec: rr.RecordingStream, path: str, t: np.ndarray, v: np.ndarray, name,
            color=None, step: bool = False) -> None:
    """Series ``v`` at ``path``: one (``v`` of shape (n,), ``name`` a string) or several
    finite at the same steps (``v`` of shape (n, k), ``name`` and ``color`` lists of k),
    at the steps where they are finite."""
    keep = np.isfinite(v) if v.ndim == 1 else np.isfinite(v).all(axis=1)
    if not v.size or not keep.any():
        return
    rec.log(path, rr.SeriesLines(names=name, colors=color,
                                 interpolation_mode="StepAfter" if step else None),
            static=True)
    rec.send_columns(path, indexes=[rr.TimeColumn(TIMELINE, duration=t[keep])],
                     columns=rr.Scalars.columns(scalars=v[keep]))


def _series_sets(rec: rr.RecordingStream, base: str, t: np.ndarray, names: list[str],
                 values: np.ndarray) -> None:
    """The series ``values[i]`` named ``names[i]`` at ``base/<k>``: series finite at the
    same steps share entity ``k``, so every row holds only finite values, as a series
    logged alone does."""
    sets: dict[bytes, list[int]] = {}
    for i, v in enumerate(values):
        finite = np.isfinite(v)
        if finite.any():
            sets.setdefault(finite.tobytes(), []).append(i)
    for k, members in enumerate(sets.values()):
        _series(rec, f"{base}/{k}", t, values[members].T, [names[i] for i in members])


def _alarm_events(method: str, tr: Trace) -> list[tuple[float, str, str]]:
    events = []
    for i, (start, stop) in enumerate(tr.alarm_intervals()):
        k = int(np.searchsorted(tr.t, start))
        channels = [c for c, a in zip(tr.channels, tr.alarm[k], strict=True) if a]
        first = "first alarm" if i == 0 else "alarm"
        events.append((start, f"{first} {method} ({', '.join(channels)}) until "
                       f"{stop:.2f} s", "ERROR"))
    return events


def _fault_events(flight: Flight) -> list[tuple[float, str, str]]:
    if flight.fault.onset_s is None:
        return []
    return [(flight.fault.onset_s, f"fault onset: {flight.fault.fault_class}", "WARN"),
            (flight.fault.end_s, "fault end", "INFO")]


def _method_entities(rec: rr.RecordingStream, method: str, tr: Trace) -> None:
    """A method's entities: its scores, thresholds, probes and overview line."""
    base = f"methods/{method}"
    _series_sets(rec, f"{base}/scores", tr.t, list(tr.channels), tr.score.T)
    finite = np.isfinite(tr.threshold)
    _series(rec, f"{base}/scores/threshold", tr.t[[0, -1]],
            np.tile(tr.threshold[finite], (2, 1)),
            [f"{c} threshold" for c, f in zip(tr.channels, finite, strict=True) if f],
            [_RED] * int(finite.sum()))
    if tr.probes:
        _series_sets(rec, f"{base}/probes", tr.t, list(tr.probes),
                     np.array(list(tr.probes.values())))
    r = ratio(tr)
    _series(rec, f"overview/{method}", tr.t, np.where(np.isinf(r), np.nan, r), method)


def _stream(flight_id: str, path: Path, provenance: dict,
            layout: rrb.Blueprint | None = None) -> rr.RecordingStream:
    """A stream to ``path`` of the recording of ``flight_id`` (its id: the files of one
    flight open as one recording), carrying ``provenance`` and the ``layout``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    rec = rr.RecordingStream(_APPLICATION, recording_id=flight_id, send_properties=False)
    rec.save(path)
    if layout is not None:
        # active, not only the default: a default is not taken up when another file of
        # the recording, opened with it, had the viewer draw a layout of its own first
        rec.send_blueprint(layout, make_active=True, make_default=True)
    rec.send_property("provenance", rr.AnyValues(
        json=json.dumps(provenance, sort_keys=True, allow_nan=False)))
    return rec


def _close(rec: rr.RecordingStream, events: list[tuple[float, str, str]]) -> None:
    """Log ``events`` (time, text, level) in time order, and close the stream."""
    if events:
        times, texts, levels = zip(*sorted(events, key=lambda e: (e[0], e[1])), strict=True)
        rec.send_columns("events", indexes=[rr.TimeColumn(TIMELINE, duration=list(times))],
                         columns=rr.TextLog.columns(text=list(texts), level=list(levels)))
    rec.flush()
    rec.disconnect()


def _flight_stream(flight: Flight, methods: list[str], signals: list[str], path: Path,
                   provenance: dict) -> rr.RecordingStream:
    """The stream of ``flight``'s own entities: its properties, blueprint (a tab per
    method of ``methods``), raw ``signals`` and overview bars."""
    raw = {}
    for s in signals:
        try:
            raw[s] = series(flight, s)
        except AlfaDataError as e:
            log.warning("%s: signal %s not recorded: %s", flight.id, s, e)
    groups = [g for g in _GROUPS if any(signal_group(s) == g for s in raw)]
    fault = flight.fault
    span = (None if fault is None or fault.onset_s is None
            else (fault.onset_s, fault.end_s))
    title = f"{fault.fault_class if fault else 'unlabelled'}: {flight.id}"
    rec = _stream(flight.id, path, provenance, blueprint(methods, groups, title, span))
    rec.send_recording_name(flight.id)
    rec.send_property("flight", rr.AnyValues(
        flight=flight.id, date=flight.date, label=flight.label,
        fault_class=fault.fault_class if fault else "unknown",
        onset_s=np.nan if fault is None or fault.onset_s is None else fault.onset_s,
        fault_end_s=np.nan if fault is None or fault.end_s is None else fault.end_s,
        git_commit=code_version()["git_commit"] or "unknown"))
    for s, (t, v) in raw.items():
        _series(rec, f"signals/{signal_group(s)}/{s}", t, v, s, step=True)
    if span is not None:
        # a bar along the top of the overview from onset to the fault's end
        _series(rec, "overview/fault", np.array(span), np.full(2, 2.9), "fault", _RED)
    _series(rec, "overview/threshold", np.array([0.0, flight.duration_s]), np.ones(2),
            "alarm level", _RED)
    return rec


def write_rerun_log(flight: Flight, traces: dict[str, Trace], signals: list[str],
                    path: str | Path, provenance: dict) -> None:
    """Write the recording of ``flight`` with the ``traces`` of each method (with
    probes), the raw ``signals`` and the run's ``provenance`` to ``path``, in one file.
    A signal the flight cannot give (a column a method excluded it for) is left out,
    and logged."""
    rec = _flight_stream(flight, list(traces), signals, Path(path), provenance)
    for method, tr in traces.items():
        _method_entities(rec, method, tr)
    # an unlabelled flight has no fault to set the alarms against: no event log
    _close(rec, [] if flight.fault is None else _fault_events(flight) + [
        e for method, tr in traces.items() for e in _alarm_events(method, tr)])


def write_flight_part(flight: Flight, methods: list[str], signals: list[str],
                      path: str | Path, provenance: dict) -> None:
    """Write the part of ``flight``'s recording that no run's changes: its properties,
    the raw ``signals``, the overview's fault bar and alarm level, the fault's events,
    and the layout, a tab for each of ``methods``. :func:`write_run_part` writes each
    run's part; rerun opens the files of one flight as one recording."""
    rec = _flight_stream(flight, methods, signals, Path(path), provenance)
    _close(rec, [] if flight.fault is None else _fault_events(flight))


def write_run_part(flight_id: str, method: str, trace: Trace, path: str | Path,
                   provenance: dict) -> None:
    """Write ``method``'s part of the recording of flight ``flight_id`` to ``path``:
    its entities from ``trace`` (scores, thresholds, intermediates, overview line) and
    its alarms in the event log, with the run's ``provenance``; no layout, which the
    flight's part (:func:`write_flight_part`) carries."""
    rec = _stream(flight_id, Path(path), provenance)
    _method_entities(rec, method, trace)
    _close(rec, _alarm_events(method, trace))
