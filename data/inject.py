r"""Sensor faults injected into fault-free ALFA flights (Heredia and Ollero, 2011, Sec. 5).

:func:`inject_sensor_fault` writes a new flight, in ALFA's on-disk format, that is a
fault-free flight with one sensor corrupted from an onset on. Only the sensor's
column of its topic changes, and only in rows recorded at or after the onset; every
other cell, row and file is the source's, byte for byte. With :math:`v` the recorded
value, :math:`r` the range (max - min) of the sensor over the source flight, :math:`m`
the magnitude and :math:`t_0` the onset:

============  =================================================  ================
kind          value from the onset                               paper
============  =================================================  ================
``stuck``     the last value recorded before the onset           stuck, constant
``zero``      0                                                  stuck at zero
``drift``     :math:`v + m r`                                    additive (drift)
``scale``     :math:`m v` (output at :math:`100 m` % of nominal) multiplicative
``noise``     :math:`v + \mathcal N(0, (m r)^2)`, seeded         (beyond)
``ramp``      :math:`v + m r (t - t_0) / 60\,\mathrm{s}`         (beyond)
============  =================================================  ================

Ground truth is a ``failure_status-sensor`` topic with one row per corrupted row
(same ``%time``), holding the sensor, kind, magnitude and source flight, so the data layer, every
method and the scoring read it as they read ALFA's own ``failure_status`` topics.
The new flight is named ``<source date-time>_<part>_sensor_<sensor>_<kind><100 m>
_at<onset s>_failure``.

The workflow builds these flights in memory (:func:`inject_flight`,
:class:`InjectedGrid`) from the parsed source flights, whenever a job needs them: the
same :class:`~.flight.Flight` that reading :func:`inject_sensor_fault`'s files gives,
array for array (the two parsers agree on every cell of ALFA, and ``repr`` round-trips).
The CSV copies are written only on request (``snakemake injected_csv``). An injected
flight's checksum is the SHA-256 of its source's checksum and its fault spec
(:func:`injected_sha256`).
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import shutil
import zlib
from collections.abc import Iterator, Mapping
from dataclasses import replace
from functools import cache
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import AlfaDataError
from .flight import Fault, Flight, Topic, assemble_flight, load_flight, parse_flight_name
from .signals import SIGNALS, not_measured

log = logging.getLogger("alfa_bench.data")

__all__ = ["KINDS", "RAMP_S", "SENSORS", "InjectedGrid", "grid_specs", "inject_flight",
           "inject_grid", "inject_sensor_fault", "injected_name", "injected_sha256"]

#: The sensors a fault can be injected into: the measured signals.
SENSORS = ("roll", "pitch", "yaw", "airspeed", "roll_rate", "pitch_rate", "yaw_rate")
KINDS = ("stuck", "zero", "drift", "scale", "noise", "ramp")
#: A ramp grows by magnitude x range every RAMP_S seconds.
RAMP_S = 60.0
GROUND_TRUTH = "failure_status-sensor"


def injected_name(source: str, sensor: str, kind: str, magnitude: float,
                  onset_s: float) -> str:
    """The folder name of the flight :func:`inject_sensor_fault` writes (an ALFA
    flight's or a converted log's, as its source)."""
    meta = parse_flight_name(source)
    size = "" if kind in ("stuck", "zero") else f"{round(100 * magnitude)}"
    aircraft = source.split("_", 1)[0]
    return (f"{aircraft}_{meta['date']}-{meta['time']}_{meta['part'] or 0}_sensor_{sensor}_"
            f"{kind}{size}_at{round(onset_s)}_failure")


def inject_sensor_fault(source: str | Path | Flight, processed: str | Path, sensor: str,
                        kind: str, magnitude: float, onset_s: float, *, topics=None,
                        seed: int = 0) -> Path:
    """Write ``source`` with ``sensor`` corrupted from ``onset_s`` (s on its flight
    clock) under ``processed``; return the new flight's folder.

    Parameters
    ----------
    source : path or Flight
        A fault-free flight (label ``no_failure``), its folder or loaded.
    sensor : str
        One of :data:`SENSORS`.
    kind : str
        One of :data:`KINDS` (table above).
    magnitude : float
        :math:`m`, a fraction of the sensor's range (drift, noise, ramp) or of its
        nominal output (scale); unused for ``stuck`` and ``zero``.
    topics : collection of str, optional
        The topics to write (default all); the sensor's and the ground truth are
        always written.
    seed : int
        Seeds the noise, with the new flight's name.
    """
    flight = source if isinstance(source, Flight) else load_flight(source)
    topic = _check_spec(flight, sensor, kind, onset_s)
    sig = SIGNALS[sensor]
    source = flight.path
    name = injected_name(flight.id, sensor, kind, magnitude, onset_s)
    dest = Path(processed) / name
    dest.mkdir(parents=True)
    values = topic.values(sig.column)
    span = float(values.max() - values.min())
    for f in sorted(source.glob(f"{flight.id}-*.csv")):
        name_of_topic = f.name[len(flight.id) + 1:-len(".csv")]
        if topics is None or name_of_topic in topics or name_of_topic == sig.topic:
            _link(f, dest / f"{name}-{name_of_topic}.csv")
    path = dest / f"{name}-{sig.topic}.csv"
    rng = np.random.default_rng([seed, zlib.crc32(name.encode())])
    times = _rewrite(path, sig.column, flight.t0_ns + round(onset_s * 1e9),
                     lambda v, held, dt: _corrupt(kind, v, held, dt, magnitude, span, rng))
    rows = [f"{t},1,{sensor},{kind},{magnitude!r},{flight.id}" for t in times]
    header = "%time,field.data,field.sensor,field.kind,field.magnitude,field.source"
    (dest / f"{name}-{GROUND_TRUTH}.csv").write_text("\n".join([header, *rows]) + "\n")
    return dest


def _check_spec(flight: Flight, sensor: str, kind: str, onset_s: float) -> Topic:
    """The sensor's topic, once the fault spec is checked against ``flight``."""
    if sensor not in SENSORS:
        raise ValueError(f"sensor must be one of {SENSORS}, got {sensor!r}")
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    if flight.fault is None or flight.fault.fault_class != "none":
        raise AlfaDataError("faults are injected into fault-free flights only",
                            flight=flight.id)
    sig = SIGNALS[sensor]
    topic = flight.topic(sig.topic)
    if not_measured(flight, [sensor]):
        raise AlfaDataError(f"{sensor} is not measured on this flight (constant over all of "
                            "it): a fault injected there would corrupt a value that is not "
                            "there", flight=flight.id, file=topic.file, column=sig.column)
    if not topic.t[0] < onset_s <= topic.t[-1]:
        raise ValueError(f"onset {onset_s} s is outside {sig.topic} "
                         f"({topic.t[0]:.2f}-{topic.t[-1]:.2f} s)")
    return topic


def inject_flight(source: Flight, processed: str | Path, sensor: str, kind: str,
                  magnitude: float, onset_s: float, *, topics=None, seed: int = 0) -> Flight:
    """The flight :func:`inject_sensor_fault` would write under ``processed``, built
    in memory from the loaded ``source``; same parameters.

    The kept topics are re-timed on the new flight's clock (its first record), as
    reading the written files would; their frames are the source's, unchanged but
    for the corrupted column, which becomes float64 as written by ``repr``. The
    corrupted topic's frame and the ground truth's are built when first asked for:
    the numbers they hold, and the fault, are handed over as reading them would give.
    """
    topic = _check_spec(source, sensor, kind, onset_s)
    sig = SIGNALS[sensor]
    name = injected_name(source.id, sensor, kind, magnitude, onset_s)
    keep = [t for t in source.topics if topics is None or t in topics or t == sig.topic]
    onset_ns = source.t0_ns + round(onset_s * 1e9)
    values = topic.values(sig.column)
    span = float(values.max() - values.min())
    rng = np.random.default_rng([seed, zlib.crc32(name.encode())])
    # the record times in ns, exactly: |t| < 1e4 s keeps t * 1e9 within float64's integers
    times = source.t0_ns + np.round(topic.t * 1e9).astype(np.int64)
    first = int(np.searchsorted(times, onset_ns))
    corrupted = values.copy()
    # the operations of _corrupt, in the same order on the same doubles, over the rows
    corrupted[first:] = _corrupt(kind, values[first:], float(values[first - 1]),
                                 (times[first:] - onset_ns) * 1e-9, magnitude, span, rng)
    corrupted.setflags(write=False)
    t0 = min(source.t0_ns + round(float(source.topics[t].t[0]) * 1e9) for t in keep)
    if t0 == source.t0_ns:      # the same clock: the times are the source's, to the bit
        clock = {t: source.topics[t].t for t in keep} | {GROUND_TRUTH: topic.t[first:]}
    else:
        clock = {t: (source.t0_ns + np.round(source.topics[t].t * 1e9).astype(np.int64) - t0)
                 * 1e-9 for t in keep} | {GROUND_TRUTH: (times[first:] - t0) * 1e-9}
    rows = len(times) - first

    def corrupted_frame() -> pd.DataFrame:
        frame = topic.frame.copy(deep=False)
        frame[sig.column] = corrupted
        return frame

    def ground_truth() -> pd.DataFrame:
        repeat = np.zeros(rows, dtype=np.intp)
        return pd.DataFrame({"field.data": np.ones(rows, np.int64),
                             "field.sensor": _text(sensor).take(repeat),
                             "field.kind": _text(kind).take(repeat),
                             "field.magnitude": np.full(rows, float(magnitude)),
                             "field.source": _text(source.id).take(repeat)})

    data, size = np.ones(rows), np.full(rows, float(magnitude))
    for v in (data, size):
        v.setflags(write=False)
    new = {t: replace(source.topics[t], flight=name, file=f"{name}-{t}.csv", t=clock[t])
           for t in keep if t != sig.topic}
    # what values() would parse from the new frames, handed over as the cache does
    new[sig.topic] = Topic(name, sig.topic, f"{name}-{sig.topic}.csv", clock[sig.topic],
                           cache(corrupted_frame), topic.lines,
                           {**topic._cache, sig.column: corrupted})
    new[GROUND_TRUTH] = Topic(name, GROUND_TRUTH, f"{name}-{GROUND_TRUTH}.csv",
                              clock[GROUND_TRUTH], cache(ground_truth),
                              np.arange(2, rows + 2),
                              {"field.data": data, "field.magnitude": size})
    fault = Fault("sensor", float(clock[GROUND_TRUTH][0]), float(clock[GROUND_TRUTH][-1]),
                  (GROUND_TRUTH,), {GROUND_TRUTH: (1,)}, sensor, kind, float(magnitude),
                  source.id)
    files = {source.topics[t].file: f"{name}-{t}.csv" for t in keep}
    repairs = [files[r.split(":", 1)[0]] + ":" + r.split(":", 1)[1]
               for r in source.repairs if r.split(":", 1)[0] in files]
    return assemble_flight(Path(processed) / name, t0, {t: new[t] for t in sorted(new)},
                           repairs, ground_truth=fault)


@cache
def _text(value: str) -> pd.api.extensions.ExtensionArray:
    """A text cell, to repeat down a column (``take``): twice as fast as converting a
    list of it, which took most of the time an injected flight took to build."""
    return pd.array([value], dtype="str")


def injected_sha256(source_sha256: str, sensor: str, kind: str, magnitude: float,
                    onset_s: float) -> str:
    """The checksum of an injected flight: its source's and its fault spec's."""
    spec = {"source": source_sha256, "sensor": sensor, "kind": kind,
            "magnitude": float(magnitude), "onset_s": float(onset_s)}
    return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()


def _unreadable(flight: Flight, sensor: str) -> str | None:
    """Why ``sensor``'s column of ``flight`` cannot be read, or None."""
    sig = SIGNALS[sensor]
    try:
        flight.topics[sig.topic].values(sig.column)
    except AlfaDataError as e:
        return f"cannot be read: {e}"
    return None


def grid_specs(sources: dict[str, Flight], manifest, sensors, faults,
               onsets) -> tuple[list[dict], list[dict]]:
    """The fault specs of the grid: every fault-free flight of ``manifest`` (loaded in
    ``sources``) with every sensor of ``sensors`` corrupted by every fault of ``faults``
    (``{"kind", "magnitude"}``) from every onset of ``onsets`` (fractions of the
    flight's duration). A sensor whose topic a flight lacks, that the flight does not
    measure (the manifest's ``not_measured``), or whose column cannot be read (a bad
    cell: the error says where) is skipped there, with a warning.
    Returns the specs (``source``, ``sensor``, ``kind``, ``magnitude``, ``onset_s``),
    and the skipped ``{"flight", "sensor", "reason"}``."""
    specs, skipped = [], []
    for row in manifest[manifest["fault_class"] == "none"].itertuples():
        source = sources[row.flight]
        dead = set(str(row.not_measured).split(";"))
        for sensor in sensors:
            reason = (f"no {SIGNALS[sensor].topic} topic"
                      if SIGNALS[sensor].topic not in source.topics else
                      "not measured (constant over the flight)" if sensor in dead else
                      _unreadable(source, sensor))
            if reason:
                log.warning("%s: %s: %s, so no faults injected", row.flight, sensor, reason)
                skipped.append({"flight": row.flight, "sensor": sensor, "reason": reason})
                continue
            specs += [{"source": row.flight, "sensor": sensor, "kind": fault["kind"],
                       "magnitude": float(fault["magnitude"]),
                       "onset_s": round(share * row.flight_s, 2)}
                      for fault in faults for share in onsets]
    return specs, skipped


class InjectedGrid(Mapping[str, Flight]):
    """The grid of :func:`grid_specs`, by flight name: each flight is built in memory
    (:func:`inject_flight`, only the topics of :data:`~.signals.SIGNALS`) when looked
    up, and not kept, so that a large corpus's grid need not fit in memory.

    Attributes
    ----------
    sha256 : dict
        Each flight's checksum (:func:`injected_sha256`), in grid order.
    skipped : list of dict
        The flight-sensor pairs left out (:func:`grid_specs`).
    """

    def __init__(self, sources: dict[str, Flight], manifest, processed: str | Path,
                 sensors, faults, onsets):
        self.sources, self.processed = sources, processed
        specs, self.skipped = grid_specs(sources, manifest, sensors, faults, onsets)
        self.specs = {injected_name(s["source"], s["sensor"], s["kind"], s["magnitude"],
                                    s["onset_s"]): s for s in specs}
        sha = dict(zip(manifest["flight"], manifest["sha256"], strict=True))
        self.sha256 = {name: injected_sha256(sha[s["source"]], s["sensor"], s["kind"],
                                             s["magnitude"], s["onset_s"])
                       for name, s in self.specs.items()}

    def __getitem__(self, name: str) -> Flight:
        spec = self.specs[name]
        return inject_flight(self.sources[spec["source"]], self.processed, spec["sensor"],
                             spec["kind"], spec["magnitude"], spec["onset_s"],
                             topics={s.topic for s in SIGNALS.values()})

    def __contains__(self, name) -> bool:        # Mapping's would build the flight
        return name in self.specs

    def __iter__(self) -> Iterator[str]:
        return iter(self.specs)

    def __len__(self) -> int:
        return len(self.specs)


def inject_grid(processed: Path, manifest, out: Path, sensors, faults,
                onsets) -> tuple[list[Path], list[dict]]:
    """The grid of :func:`grid_specs` over the flights under ``processed``, written as
    ALFA-format folders under ``out`` (only the topics of :data:`~.signals.SIGNALS`):
    the CSV copies of :class:`InjectedGrid`. Returns the new folders, and the
    skipped pairs."""
    topics = {s.topic for s in SIGNALS.values()}
    sources = {name: load_flight(Path(processed) / name)
               for name in manifest.loc[manifest["fault_class"] == "none", "flight"]}
    specs, skipped = grid_specs(sources, manifest, sensors, faults, onsets)
    written = [inject_sensor_fault(sources[spec["source"]], out, spec["sensor"],
                                   spec["kind"], spec["magnitude"], spec["onset_s"],
                                   topics=topics) for spec in specs]
    return written, skipped


def _corrupt(kind, v, held, dt, m, span, rng):
    """The corrupted value of a row (``v``, ``dt`` floats) or of many (arrays)."""
    match kind:
        case "stuck":
            return held
        case "zero":
            return 0.0
        case "drift":
            return v + m * span
        case "scale":
            return m * v
        case "noise":       # one draw per row, in row order, for a row or for many
            return v + rng.normal(0.0, m * span, size=np.shape(v) or None)
        case "ramp":
            return v + m * span * dt / RAMP_S


def _link(src: Path, dst: Path) -> None:
    """``dst`` with the bytes of ``src``: a hard link where the file system allows."""
    try:
        os.link(src, dst)
    except OSError:
        shutil.copyfile(src, dst)


def _rewrite(path: Path, column: str, onset_ns: int, corrupt) -> list[int]:
    """Replace ``column`` in the rows of ``path`` at or after ``onset_ns`` by
    ``corrupt(value, last value before onset, seconds since onset)``; every other
    byte is kept. Returns the ``%time`` of the rows changed."""
    text = path.read_text()
    path.unlink()          # it may be a hard link to the source
    lines = text.split("\n")
    j = lines[0].split(",").index(column)
    held, changed = None, []
    for i in range(1, len(lines)):
        if not lines[i]:
            continue
        cells = lines[i].split(",")
        t = int(cells[0])
        if t < onset_ns:
            held = float(cells[j])
            continue
        cells[j] = repr(float(corrupt(float(cells[j]), held, (t - onset_ns) * 1e-9)))
        lines[i] = ",".join(cells)
        changed.append(t)
    path.write_text("\n".join(lines))
    return changed
