"""Run a configured method over one flight and describe the result as a record.

The record is what ``results/detections/{method}/{flight}.json`` holds.
"""

from __future__ import annotations

import json
from pathlib import Path

from alfa_bench.data import Flight
from alfa_bench.methods import make_detector, run_detector

from .provenance import provenance
from .scoring import flight_outcome

__all__ = ["detection_record", "read_records", "write_record"]


def detection_record(method: str, spec: dict, flight: Flight, flight_sha256: str) -> dict:
    """Run ``spec`` (``{"detector": name, "params": {...}}``) on ``flight``."""
    if flight.fault is None:
        raise ValueError(f"flight {flight.id} has no ground truth and cannot be scored")
    detector = make_detector(spec["detector"], spec.get("params"))
    trace = run_detector(detector, flight)
    onset = flight.fault.onset_s
    first = trace.first_alarm_s()
    outcome = flight_outcome(onset, first)
    return {
        "flight": flight.id,
        "method": method,
        "detector": spec["detector"],
        "parameters": detector.get_params(),
        "fault_class": flight.fault.fault_class,
        "onset_s": onset,
        "fault_end_s": flight.fault.end_s,
        "first_alarm_s": first,
        "detection_s": first - onset if outcome == "TP" else None,
        "outcome": outcome,
        "alarm_intervals": trace.alarm_intervals(),
        "pair_first_alarm_s": {ch: trace.first_alarm_s(i)
                               for i, ch in enumerate(trace.channels)},
        "pair_armed_s": {ch: trace.armed_s(i) for i, ch in enumerate(trace.channels)},
        "grid": {"rate_hz": detector.rate_hz, "samples": int(trace.t.size),
                 "start_s": float(trace.t[0]), "stop_s": float(trace.t[-1])},
        "repairs": list(flight.repairs),
        "calibration_flights": [],
        "provenance": provenance(spec, {"flight_sha256": flight_sha256}),
    }


def write_record(record: dict, path: Path) -> None:
    """Write ``record`` as deterministic JSON (sorted keys, no NaN)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(record, sort_keys=True, indent=1, allow_nan=False, default=list)
    path.write_text(text + "\n")


def read_records(folders) -> list[dict]:
    """All records in the given ``results/detections/{method}`` folders."""
    return [json.loads(p.read_text()) for d in folders for p in sorted(Path(d).glob("*.json"))]
