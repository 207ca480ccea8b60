"""Detectability of the injected sensor faults: per method, sensor, kind and magnitude.

Every injected flight is a fault-free flight with one sensor corrupted from an onset
(:mod:`alfa_bench.data.inject`), scored as ALFA's flights are
(:func:`~.scoring.flight_outcome`): detected (first alarm at or after the onset),
alarmed early (first alarm before it: a false alarm on the real fault-free data
before the onset), or missed. The detectability curve of a method is its detection
rate against the fault's size: the drift as a fraction of the sensor's range, the
scale fault as the lost fraction of the output (:math:`1 - m`).

A method that false-alarms on fault-free flight also "detects" a fault it cannot see,
when its first false alarm falls after the onset. The *chance rate* measures this: the
share of the injected flights whose source flight, run as it was recorded, has its
first alarm at or after the same onset. A detection rate means something only above
it.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import pandas as pd

from alfa_bench.render import fmt, markdown

from .scoring import flight_outcome

__all__ = ["EMPTY", "by_fault", "detectability_markdown", "detectability_table",
           "fault_name"]

_KEYS = ["method", "sensor", "kind", "magnitude"]
_COUNTS = ["flights", "detected", "alarmed_before_onset", "missed", "detection_rate",
           "chance_rate", "mean_detection_s", "max_detection_s"]

#: what the table and figure say when the grid is empty
EMPTY = ("No injected sensor fault was scored: sensor faults are injected into fault-free "
         "flights, and this corpus has none with the configured sensors measured "
         "(results/injected/skipped.csv lists the pairs left out).")


def detectability_table(records: Iterable[dict], manifest: pd.DataFrame,
                        clean: list[dict]) -> pd.DataFrame:
    """Per method, sensor, kind and magnitude: flights, detected, alarmed before the
    onset, missed, detection rate, chance rate (from ``clean``, the records of the
    source flights) and mean and max detection time."""
    # a dict per flight: a DataFrame row lookup per record took most of the table's time
    info = manifest.set_index("flight")[["fault_source", "fault_sensor", "fault_kind",
                                         "fault_magnitude"]].to_dict("index")
    first = {(r["method"], r["flight"]): r["first_alarm_s"] for r in clean}
    rows = []
    for r in records:
        row = info[r["flight"]]
        chance = flight_outcome(r["onset_s"], first[r["method"], row["fault_source"]])
        rows.append({"method": r["method"], "sensor": row["fault_sensor"],
                     "kind": row["fault_kind"], "magnitude": float(row["fault_magnitude"]),
                     "outcome": r["outcome"], "detection_s": r["detection_s"],
                     "chance": chance == "TP"})
    flights = pd.DataFrame(rows, columns=[*_KEYS, "outcome", "detection_s", "chance"])
    out = []
    for key, g in flights.groupby(_KEYS, sort=False):
        times = g["detection_s"].dropna().astype(float)
        out.append({**dict(zip(_KEYS, key, strict=True)), "flights": len(g),
                    "detected": int((g["outcome"] == "TP").sum()),
                    "alarmed_before_onset": int((g["outcome"] == "FP+FN").sum()),
                    "missed": int((g["outcome"] == "FN").sum()),
                    "detection_rate": float((g["outcome"] == "TP").mean()),
                    "chance_rate": float(g["chance"].mean()),
                    "mean_detection_s": float(times.mean()) if len(times) else np.nan,
                    "max_detection_s": float(times.max()) if len(times) else np.nan})
    return pd.DataFrame(out, columns=[*_KEYS, *_COUNTS])


def by_fault(table: pd.DataFrame) -> pd.DataFrame:
    """Over all sensors: per method and fault, detected share and mean time."""
    g = table.groupby(["method", "kind", "magnitude"], sort=False)
    out = g[["flights", "detected", "alarmed_before_onset"]].sum()
    out["detection_rate"] = out["detected"] / out["flights"]
    chance = table.assign(c=table["chance_rate"] * table["flights"])
    out["chance_rate"] = (chance.groupby(["method", "kind", "magnitude"], sort=False)["c"]
                          .sum() / out["flights"])
    weighted = table.assign(w=table["mean_detection_s"] * table["detected"])
    out["mean_detection_s"] = (weighted.groupby(["method", "kind", "magnitude"],
                                                sort=False)["w"].sum(min_count=1)
                               / out["detected"].replace(0, np.nan))
    return out.reset_index()


def fault_name(kind: str, magnitude: float) -> str:
    if kind in ("stuck", "zero"):
        return kind
    return f"{kind} {100 * magnitude:g} %"


def detectability_markdown(table: pd.DataFrame) -> str:
    """Per fault, each method's detection rate (detected / flights, over all sensors),
    its chance rate and mean detection time; then per sensor, each method's rate over
    all faults."""
    if table.empty:
        return EMPTY + "\n"
    by = by_fault(table)
    methods = list(dict.fromkeys(by["method"]))
    faults = list(dict.fromkeys(zip(by["kind"], by["magnitude"], strict=True)))
    idx = by.set_index(["method", "kind", "magnitude"])
    rows = []
    for kind, m in faults:
        cells = [fault_name(kind, m)]
        for method in methods:
            r = idx.loc[(method, kind, m)]
            cells.append(f"{fmt(float(r['detection_rate']), True, 0)} "
                         f"[{fmt(float(r['chance_rate']), True, 0)}] "
                         f"({fmt(float(r['mean_detection_s']), digits=1)} s)")
        rows.append(cells)
    per_sensor = table.groupby(["sensor", "method"], sort=False)[["detected", "flights"]].sum()
    rate = per_sensor["detected"] / per_sensor["flights"]
    sensor_rows = [[s, *[fmt(float(rate.loc[(s, m)]), True, 0) for m in methods]]
                   for s in dict.fromkeys(table["sensor"])]
    return markdown([
        ("Detection rate % [chance rate %] (mean detection time) per injected fault, "
         "over all sensors",
         ["fault", *methods], rows),
        ("Detection rate % per sensor, over all faults", ["sensor", *methods], sensor_rows)])
