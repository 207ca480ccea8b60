"""The flight manifest: one row per flight found, with its ground truth and subsets.

Subsets (a flight may be in several):

``all``
    every flight with ground truth (a labelled fault, or ``no_failure``);
``icra22``
    the 22 flights of Keipour et al., ICRA 2019: ALFA's flights recorded up to
    2018-09-11 inclusive, with ground truth, not ``with_emr_traj``;
``no_emr`` / ``emr``
    flights with ground truth without / with the emergency trajectory, whose
    commands change at the fault (reported apart, as the ALFA notes advise).

Nothing here lists flights by name: the subsets are rules over what is found.

A flight that cannot be read is not in the manifest. :func:`scan_flights` reports
it as a failure row instead (with the subsets its name says it would have been
in, so the tables can show it as excluded); :func:`build_manifest` stops at it.
"""

from __future__ import annotations

import hashlib
import json
import logging
import math
from importlib import resources
from pathlib import Path

import jsonschema
import pandas as pd

from .cache import cache_path, write_cached
from .errors import FAILURE_COLUMNS, AlfaDataError, failure_row
from .flight import Flight, entries, find_flights, load_flight, not_a_flight, parse_flight_name
from .signals import check_signals, not_measured

__all__ = ["ICRA22_LAST_DATE", "SUBSETS", "build_manifest", "flight_sha256", "in_subset",
           "manifest_of",
           "manifest_row", "name_subsets", "read_manifest", "scan_flights", "subset_flights",
           "validate_manifest"]

log = logging.getLogger("alfa_bench.data")

ICRA22_LAST_DATE = "2018-09-11"

SUBSETS = {
    "all": lambda r: r["ground_truth"],
    "icra22": lambda r: (r["ground_truth"] and r["flight"].startswith("carbonZ_")
                         and r["date"] <= ICRA22_LAST_DATE and not r["emergency_trajectory"]),
    "no_emr": lambda r: r["ground_truth"] and not r["emergency_trajectory"],
    "emr": lambda r: r["ground_truth"] and r["emergency_trajectory"],
}

COLUMNS = ["flight", "date", "time", "label", "fault_class", "ground_truth",
           "emergency_trajectory", "onset_s", "fault_end_s", "fault_s", "flight_s",
           "pre_fault_s", "n_topics", "repairs", "sha256", "subsets", "fault_sensor",
           "fault_kind", "fault_magnitude", "fault_source", "not_measured"]


def _schema() -> dict:
    return json.loads(resources.files(__package__).joinpath("manifest.schema.json").read_text())


def flight_sha256(path: Path) -> str:
    """SHA-256 over the flight's files, each as ``name\\0content``, sorted by name."""
    h = hashlib.sha256()
    for f in sorted(Path(path).glob("*.csv")):
        h.update(f.name.encode() + b"\0")
        h.update(f.read_bytes())
    return h.hexdigest()


def manifest_row(flight: Flight, sha256: str | None = None) -> dict:
    """The manifest row of a loaded flight; ``sha256`` stands for its files' checksum
    where it has none on disk (an injected flight built in memory)."""
    fault = flight.fault
    onset = fault.onset_s if fault else None
    if fault is None:
        pre = None
    elif onset is None:
        pre = flight.duration_s
    else:
        pre = onset
    row = {
        "flight": flight.id,
        "date": flight.date,
        "time": parse_flight_name(flight.id)["time"],
        "label": flight.label,
        "fault_class": fault.fault_class if fault else "unknown",
        "ground_truth": fault is not None,
        "emergency_trajectory": flight.emergency_trajectory,
        "onset_s": onset,
        "fault_end_s": fault.end_s if fault else None,
        "fault_s": (fault.end_s - onset) if onset is not None else None,
        "flight_s": flight.duration_s,
        "pre_fault_s": pre,
        "n_topics": len(flight.topics),
        "repairs": len(flight.repairs),
        "sha256": sha256 or flight_sha256(flight.path),
        "fault_sensor": (fault.sensor or "") if fault else "",
        "fault_kind": (fault.kind or "") if fault else "",
        "fault_magnitude": fault.magnitude if fault else None,
        "fault_source": (fault.source or "") if fault else "",
        # catalogue signals constant over the whole flight (measured airspeed from
        # 2018-09-11 on): a method skips its channels on them
        "not_measured": ";".join(not_measured(flight)),
    }
    row["subsets"] = ";".join(name for name, rule in SUBSETS.items() if rule(row))
    return row


def name_subsets(flight: str) -> str:
    """The subsets a flight's name puts it in, were its ground truth readable
    (empty for a name that is not an ALFA flight name)."""
    try:
        meta = parse_flight_name(flight)
    except AlfaDataError:
        return ""
    row = {"flight": flight, "ground_truth": meta["label"] != "no_ground_truth",
           "date": meta["date"],
           "emergency_trajectory": str(meta["label"]).endswith("with_emr_traj")}
    return ";".join(name for name, rule in SUBSETS.items() if rule(row))


def _row(path: Path, cache: Path | None, signals=None) -> dict:
    flight = load_flight(path)
    check_signals(flight, signals)
    row = manifest_row(flight)
    if cache is not None:
        write_cached(flight, cache_path(cache, flight.id), row["sha256"])
    return row


def scan_flights(processed: str | Path, cache: str | Path | None = None, signals=None
                 ) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Load every flight under ``processed``: the validated manifest of those that
    load, and a failures table (:data:`~.errors.FAILURE_COLUMNS` and ``subsets``)
    of those that do not, each also logged. Every entry of ``processed`` but hidden
    ones is one or the other: one that is no flight folder (:func:`~.flight.
    not_a_flight`) is a failure saying why. With ``cache``, each flight that loads is
    also written there (:mod:`.cache`). ``signals`` are those checked
    (:func:`~.signals.check_signals`; default the catalogue)."""
    rows, failures = [], []
    for path in entries(Path(processed)):
        try:
            if (why := not_a_flight(path)) is not None:
                raise AlfaDataError(why, flight=path.name)
            rows.append(_row(path, cache, signals))
        except AlfaDataError as e:
            log.error("flight %s excluded: %s", path.name, e)
            failures.append({**failure_row(e, "load"), "flight": path.name,
                             "subsets": name_subsets(path.name)})
    if not rows:
        raise AlfaDataError(f"no readable flights under {processed} "
                            f"({len(failures)} could not be read)")
    return manifest_of(rows), pd.DataFrame(failures, columns=[*FAILURE_COLUMNS, "subsets"])


def manifest_of(rows: list[dict]) -> pd.DataFrame:
    """The validated manifest of ``rows`` (:func:`manifest_row`); it may be empty."""
    manifest = pd.DataFrame(rows, columns=COLUMNS)
    validate_manifest(manifest)
    return manifest


def build_manifest(processed: str | Path, allow_empty: bool = False,
                   cache: str | Path | None = None, signals=None) -> pd.DataFrame:
    """Load every flight under ``processed`` and return the validated manifest;
    the first flight that cannot be read raises its :class:`AlfaDataError`. No flight
    at all is an error too, unless ``allow_empty`` (the injected grid of a corpus
    without fault-free flights). With ``cache``, each flight is also written there;
    ``signals`` as for :func:`scan_flights`."""
    rows = [_row(p, cache, signals) for p in find_flights(Path(processed))]
    if not rows and not allow_empty:
        raise AlfaDataError(f"no flights found under {processed}")
    return manifest_of(rows)


def validate_manifest(manifest: pd.DataFrame) -> None:
    """Check every row against ``manifest.schema.json``; raise AlfaDataError if not."""
    schema = _schema()
    validator = jsonschema.Draft202012Validator(schema)
    for record in manifest.to_dict(orient="records"):
        clean = {k: (None if isinstance(v, float) and math.isnan(v) else v)
                 for k, v in record.items()}
        errors = sorted(validator.iter_errors(clean), key=lambda e: list(e.path))
        if errors:
            e = errors[0]
            raise AlfaDataError(f"manifest row does not match the schema: {e.message}",
                                flight=str(record.get("flight")),
                                column=".".join(map(str, e.path)) or None)
    if manifest["flight"].duplicated().any():
        raise AlfaDataError("manifest lists a flight twice: "
                            f"{manifest.loc[manifest['flight'].duplicated(), 'flight'].iloc[0]}")


def read_manifest(path: str | Path) -> pd.DataFrame:
    """Read ``results/flights.csv`` back with its types, and validate it."""
    text = {c: str for c in ("date", "time", "subsets", "fault_sensor", "fault_kind",
                             "fault_source", "not_measured")}
    manifest = pd.read_csv(path, dtype=text, keep_default_na=False, na_values={
        c: [""] for c in ("onset_s", "fault_end_s", "fault_s", "pre_fault_s",
                          "fault_magnitude")})
    for c in ("subsets", "fault_sensor", "fault_kind", "fault_source", "not_measured"):
        manifest[c] = manifest[c].fillna("")
    validate_manifest(manifest)
    return manifest


def subset_flights(manifest: pd.DataFrame, subset: str) -> list[str]:
    """Flights of ``subset``, in manifest order."""
    if subset not in SUBSETS:
        raise KeyError(f"unknown subset {subset!r}; known: {sorted(SUBSETS)}")
    return in_subset(manifest, subset)["flight"].tolist()


def in_subset(rows: pd.DataFrame, subset: str) -> pd.DataFrame:
    """The ``rows`` (of the manifest, ``failures.csv`` or ``left_out.csv``) whose
    ``subsets`` name ``subset``; an empty cell names none."""
    return rows[rows["subsets"].fillna("").astype(str).str.split(";").apply(
        lambda s: subset in s)]
