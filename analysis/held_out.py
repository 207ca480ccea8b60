"""Leave-one-group-out folds: no flight is scored by a model or threshold that saw it.

Each fold holds out one group of flights (a day, by default, since flights of one
day share the aircraft's trim, wind and the segments of one recording; or one
recording, the flight name's timestamp, as a public study of ALFA does; or one
flight) and
calibrates on the fault-free data of every other flight with ground truth (or, for a
supervised detector, on those flights whole, with their labels).
:func:`check_held_out` checks, before every fit, that no segment comes from the
group scored.
"""

from __future__ import annotations

import pandas as pd

from alfa_bench.methods import CalibrationError

__all__ = ["GROUPINGS", "HeldOutError", "TooFewGroupsError", "check_held_out", "folds",
           "group_labels", "groups_of", "own_calibration"]

#: the manifest columns whose values, joined by "-", name a flight's group
GROUPINGS = {"date": ("date",), "recording": ("date", "time"), "flight": ("flight",)}


def own_calibration(calibration: dict, spec: dict) -> dict:
    """The calibration settings of the run ``spec``: ``calibration``, with the run's own
    (``calibration: {group_by: ...}`` on the run) in their place."""
    return {**calibration, **spec.get("calibration", {})}


def group_labels(manifest: pd.DataFrame, group_by: str) -> pd.Series:
    """Each flight's group under ``group_by`` (one of :data:`GROUPINGS`), as strings."""
    if group_by not in GROUPINGS:
        raise ValueError(f"group_by must be one of {sorted(GROUPINGS)}, got {group_by!r}")
    columns = [manifest[c].astype(str) for c in GROUPINGS[group_by]]
    return columns[0].str.cat(columns[1:], sep="-") if len(columns) > 1 else columns[0]


class TooFewGroupsError(CalibrationError):
    """The flights fall in fewer than two groups: none can be left out."""


def folds(manifest: pd.DataFrame, group_by: str) -> dict[str, tuple[list[str], list[str]]]:
    """Group -> (flights it scores, flights that calibrate it), over flights with
    ground truth, in manifest order."""
    labelled = manifest[manifest["ground_truth"]]
    groups = group_labels(labelled, group_by).to_numpy()
    found = len(dict.fromkeys(groups))
    if found < 2:
        raise TooFewGroupsError(f"calibration needs flights from at least two {group_by} groups; "
                         f"found {found}")
    flights = labelled["flight"].to_numpy()
    # in manifest order (scikit-learn's LeaveOneGroupOut gives the same folds, but every
    # job that calibrates would pay its import, ~0.7 s, for these three lines)
    return {g: (flights[groups == g].tolist(), flights[groups != g].tolist())
            for g in dict.fromkeys(groups)}


def groups_of(scored: pd.DataFrame, train: pd.DataFrame, group_by: str) -> pd.Series:
    """The group of each flight of ``scored``, whose fold scores it: its own, but an
    injected flight's (``fault_source`` set) is its source's group in ``train``, so
    that it is scored by the fold that left its source out, whatever the grouping."""
    own = group_labels(scored, group_by)
    if "fault_source" not in scored:
        return own
    source = scored["fault_source"].fillna("").astype(str)
    of_source = dict(zip(train["flight"], group_labels(train, group_by), strict=True))
    injected = source != ""
    unknown = sorted(set(source[injected]) - set(of_source))
    if unknown:
        raise ValueError(f"injected flights' sources are not among the calibration "
                         f"flights: {unknown}")
    return own.where(~injected, source.map(of_source))


class HeldOutError(RuntimeError):
    """A fit was about to see a flight of the group it scores: a bug, never data."""


def check_held_out(segments, fold: str, scored: list[str], group: dict[str, str]) -> None:
    """Raise :class:`HeldOutError` if a segment (anything with a ``flight``) comes from
    a flight of ``scored`` or of group ``fold`` (``group`` maps flights to groups)."""
    seen, scored = {seg.flight for seg in segments}, set(scored)
    inside = sorted(f for f in seen if f in scored or group.get(f) == fold)
    unknown = sorted(seen - set(group))
    if inside or unknown:
        what = (f"flights of the scored group: {inside}" if inside else
                f"flights of no known group: {unknown}")
        raise HeldOutError(f"fold {fold}: calibration would see {what}")
