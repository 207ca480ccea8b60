"""Tidy long tables as Parquet, with their provenance in the file's metadata.

The per-flight outcomes and the detection records are the tables most worth querying
(DuckDB, pandas, Arrow), so they also come as Parquet: typed columns, and the
provenance block under the schema metadata key ``provenance``
(:func:`~.provenance.read_provenance` reads it back).
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from alfa_bench.analysis.blocks import block

__all__ = ["record_rows", "records_table", "write_parquet"]


def records_table(records: list[dict]) -> pd.DataFrame:
    """One row per detection record: what it ran, on which flight, how it was
    calibrated, and what it found (first alarm, the paper's outcome, the isolated
    sensor). The nested parts (channels, intervals, fitted values) stay in the JSON."""
    return pd.DataFrame(record_rows(records))


def record_rows(records: list[dict]) -> list[dict]:
    """The rows of :func:`records_table`, in the order of ``records``: a run's alone
    are its part of the table."""
    rows = []
    for r in records:
        cal = r.get("calibration") or {}
        rows.append({
            "method": r["method"], "detector": r["detector"], "role": r["role"],
            "block": block(r), "reads_actuators": bool(r["reads_actuators"]),
            "flight": r["flight"], "fault_class": r["fault_class"],
            "onset_s": r["onset_s"], "fault_end_s": r["fault_end_s"],
            "first_alarm_s": r["first_alarm_s"], "detection_s_paper": r["detection_s"],
            "outcome_paper": r["outcome"], "isolated_sensor": r.get("isolated_sensor"),
            "calibration_fold": cal.get("fold"), "supervised": bool(cal.get("supervised")),
            "calibration_flights": len(cal.get("flights", [])),
            "grid_rate_hz": r["grid"]["rate_hz"], "grid_samples": r["grid"]["samples"],
        })
    return rows


def write_parquet(table: pd.DataFrame, path: str | Path, prov: dict) -> None:
    """Write ``table`` to ``path`` with ``prov`` in the schema metadata; deterministic
    (no pandas index, no creation time)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    arrow = pa.Table.from_pandas(table, preserve_index=False)
    meta = {**(arrow.schema.metadata or {}),
            b"provenance": json.dumps(prov, sort_keys=True, allow_nan=False).encode()}
    pq.write_table(arrow.replace_schema_metadata(meta), path)
