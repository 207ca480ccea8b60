"""Which sensor, or which actuator, a detection points at: isolation scoring.

A detector isolates through its structure (Heredia and Ollero's bank: one estimator
per output, so a sensor fault moves its own residual; RLS-ARX's one model per
input/output pair): at the first alarm at or after the onset, the alarming channel
with the highest score-to-threshold ratio names the measured signal it scores
(:meth:`~alfa_bench.methods.Detector.channel_outputs`), which names a sensor
(:func:`measured_sensor`). For ALFA's actuator faults, the sensor names the control
axis it measures and so the actuator class that acts on that axis first
(:data:`SENSOR_ACTUATOR`): roll → aileron, pitch → elevator, yaw and lateral specific
force → rudder, airspeed, longitudinal specific force, climb rate and height →
engine. A flight with no
alarm from the onset on is ``missed``. Isolation is judged
on the response to the fault alone: a false alarm before the onset is counted by the
detection scores, not here.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import pandas as pd

from alfa_bench.data import SIGNALS
from alfa_bench.data.inject import SENSORS
from alfa_bench.methods import Trace
from alfa_bench.render import fmt, markdown

__all__ = ["MISSED", "SENSOR_ACTUATOR", "confusion", "isolate", "isolation_markdown",
           "isolation_rows", "measured_sensor", "named_class", "names_class"]

_ACTUATORS = ["engine", "aileron", "elevator", "rudder"]

MISSED = "missed"
SENSOR_ACTUATOR = {"roll": "aileron", "roll_rate": "aileron", "pitch": "elevator",
                   "pitch_rate": "elevator", "yaw": "rudder", "yaw_rate": "rudder",
                   "airspeed": "engine", "accel_x": "engine", "accel_y": "rudder",
                   "vel_up": "engine", "rel_alt": "engine"}


def measured_sensor(signal: str) -> str:
    """The sensor whose readings ``signal`` is made of: ``roll_error`` is the roll
    sensor's reading minus a command. A name of :data:`~alfa_bench.data.inject.SENSORS`
    (the sensors faults are injected into), else the sensor signal itself (the specific
    force ``accel_x``)."""
    sig = SIGNALS[signal]
    for name in SENSORS:
        s = SIGNALS[name]
        if (s.topic, s.column) == (sig.topic, sig.column):
            return name
    if sig.kind == "sensor":
        return signal
    raise KeyError(f"signal {signal!r} reads no sensor")


def isolate(trace: Trace, onset_s: float, outputs: dict[str, str]) -> str | None:
    """The sensor that ``trace`` isolates for a fault from ``onset_s``, or
    :data:`MISSED`; ``outputs`` maps each channel to the signal it scores. None if
    the alarming channel scores no sensor (the emulation oracle's servo outputs)."""
    alarmed = trace.alarm.any(axis=1) & (trace.t >= onset_s)
    if not alarmed.any():
        return MISSED
    k = int(np.argmax(alarmed))
    r = np.where(trace.alarm[k], _ratio_row(trace, k), -np.inf)
    try:
        return measured_sensor(outputs[trace.channels[int(np.argmax(r))]])
    except KeyError:
        return None


def named_class(record: dict) -> str | None:
    """The actuator class that a record's first alarm from the onset points at: the one
    acting on the axis its isolated sensor measures (:data:`SENSOR_ACTUATOR`). None where
    it missed, or alarmed on a channel that scores no sensor or no control axis."""
    return SENSOR_ACTUATOR.get(record.get("isolated_sensor") or MISSED)


def names_class(record: dict) -> bool:
    """Whether that class is the flight's fault class (either of a combined one): a
    detection by a channel that can see the fault, not by a model of another axis."""
    named = named_class(record)
    return named is not None and named in record["fault_class"].split("+")


def _ratio_row(trace: Trace, k: int) -> np.ndarray:
    """Score over threshold of every channel at step ``k``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return trace.score[k] / trace.threshold


def isolation_rows(records: Iterable[dict], truth: str) -> pd.DataFrame:
    """Per record of a faulty flight: method, flight, the ``true`` sensor (``truth=
    "sensor"``, from ``fault_sensor``) or actuator class (``truth="actuator"``), and
    the ``predicted`` one, from the record's ``isolated_sensor`` (:func:`isolate`)."""
    rows = []
    for r in records:
        if r["fault_class"] == "none" or r["onset_s"] is None:
            continue
        sensor = r["isolated_sensor"]
        if sensor is None:
            raise ValueError(f"{r['method']} on {r['flight']}: its alarm scores no sensor, "
                             "so it cannot be scored for isolation")
        if truth == "sensor":
            true, predicted = r["fault_sensor"], sensor
        else:
            true, predicted = r["fault_class"], SENSOR_ACTUATOR.get(sensor, MISSED)
        rows.append({"method": r["method"], "flight": r["flight"], "true": true,
                     "predicted": predicted,
                     "correct": predicted != MISSED and predicted in true.split("+")})
    return pd.DataFrame(rows, columns=["method", "flight", "true", "predicted", "correct"])


def confusion(rows: pd.DataFrame, labels: list[str]) -> dict[str, pd.DataFrame]:
    """Per method, counts of true (rows) against predicted (columns, then ``missed``)."""
    out = {}
    for method, g in rows.groupby("method", sort=False):
        table = pd.crosstab(g["true"], g["predicted"])
        trues = [x for x in dict.fromkeys([*labels, *g["true"]]) if x in set(g["true"])]
        out[method] = table.reindex(index=trues, columns=[*labels, MISSED], fill_value=0)
    return out


def isolation_markdown(rows: pd.DataFrame, truth: str) -> str:
    """Per method, its confusion matrix (true rows, isolated columns) and isolation
    accuracy: correct over all faulty flights, and over those it responded to."""
    labels = list(SENSORS) if truth == "sensor" else _ACTUATORS
    labels = [x for x in labels if x in set(rows["predicted"]) | set(
        rows["true"].str.split("+").explode())]
    sections = []
    for method, table in confusion(rows, labels).items():
        g = rows[rows["method"] == method]
        responded = g[g["predicted"] != MISSED]
        share = fmt(float(g["correct"].mean()), True, 0)
        of_responded = fmt(float(responded["correct"].mean()) if len(responded) else None,
                            True, 0)
        body = [[true, *map(str, counts)] for true, counts in zip(
            table.index, table.to_numpy().tolist(), strict=True)]
        sections.append((f"`{method}`: isolated correctly {share} % of {len(g)} faults, "
                         f"{of_responded} % of the {len(responded)} it responded to",
                         ["true \\ isolated", *table.columns], body))
    return markdown(sections)
