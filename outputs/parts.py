"""A run's part of a table that every run's results make up, written by the run's own
job (``results/parts/<table>/<run>.csv`` or ``.jsonl``), and the parts read back, in
run order, for the table's rule to merge: so that a changed run recomputes its own part
and the merge, not every run's.

A part the merge only stacks is a CSV: pandas reads it back with the types it was
written from (numbers, booleans, strings; an empty cell is NaN, as it was written).
A part whose rows the merge makes a table of again, where an empty string and a
missing value are not the same (the per-flight table), keeps its rows as JSON Lines:
each row a JSON object with its keys in order, so that the merged table is built from
the very values the table of every run at once is built from.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["read_part_rows", "read_parts", "write_part", "write_part_rows"]


def write_part(table: pd.DataFrame, path: str | Path) -> None:
    """Write the part ``table`` to ``path`` as CSV."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(path, index=False)


def read_parts(paths) -> pd.DataFrame:
    """The CSV parts at ``paths``, stacked in that order. A part with no rows adds
    none, nor its types; where every part is empty, the first's columns."""
    frames = []
    for path in paths:
        try:
            # only an empty cell is missing: a string such as "none" or "NA" stays one
            frames.append(pd.read_csv(path, keep_default_na=False, na_values=[""]))
        except pd.errors.EmptyDataError:      # a table of no rows and no columns
            frames.append(pd.DataFrame())
    filled = [f for f in frames if len(f)]
    if not filled:
        return frames[0] if frames else pd.DataFrame()
    return pd.concat(filled, ignore_index=True)


def _plain(value):
    """A NumPy scalar as the Python value JSON writes."""
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


def write_part_rows(rows: list[dict], path: str | Path) -> None:
    """Write the part's ``rows`` to ``path`` as JSON Lines, each row's keys in order."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with Path(path).open("w") as f:
        for row in rows:
            f.write(json.dumps(row, default=_plain) + "\n")


def read_part_rows(paths) -> list[dict]:
    """The rows of the JSON Lines parts at ``paths``, in that order."""
    rows = []
    for path in paths:
        with Path(path).open() as f:
            rows += map(json.loads, f)
    return rows
