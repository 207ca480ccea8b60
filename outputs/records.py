"""A method's run written to disk, and read back: its detection records
(``results/detections/{method}/{flight}.json``, or one JSON Lines file for the injected
grid), its failures, traces, recording parts and figure panels
(:func:`write_detections`, which runs :func:`~alfa_bench.analysis.detections.detect_all`).
"""

from __future__ import annotations

import json
import logging
from collections.abc import Iterator, Mapping
from pathlib import Path

import pandas as pd

from alfa_bench.analysis.detections import detect_all
from alfa_bench.analysis.provenance import provenance, run_provenance
from alfa_bench.data import FAILURE_COLUMNS, Flight

from .provenance import read_table, stamp
from .traces import write_trace

__all__ = ["INJECTED_RECORDS", "RUN_RECORD", "count_records", "iter_records", "read_failures",
           "read_records", "read_run_record", "record_paths", "write_detections",
           "write_record"]

log = logging.getLogger(__name__)

#: in an injected-detections folder, what its records share: each fold's calibration
#: and the run's provenance, written once instead of in each of thousands of records
RUN_RECORD = "run.json"
#: in an injected-detections folder, its records: one JSON object a line, by flight name
#: (thousands of small files cost more to write, list and checksum than the records)
INJECTED_RECORDS = "records.jsonl"


def write_record(record: dict, path: Path) -> None:
    """Write ``record`` as deterministic JSON (sorted keys, no NaN)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(record, sort_keys=True, indent=1, allow_nan=False, default=list)
    path.write_text(text + "\n")


def read_records(folders) -> list[dict]:
    """All records in the given ``results/detections/{method}`` folders."""
    return list(iter_records(folders))


def record_paths(folder) -> list[Path]:
    """The record files of a real flights' detections folder, by name."""
    return sorted(Path(folder).glob("*.json"))


def iter_records(folders) -> Iterator[dict]:
    """The records of :func:`read_records`, one at a time, so that memory does not
    grow with the injected grid (145,000 records at 16 times ALFA's flights). An
    injected-detections folder holds its records in :data:`INJECTED_RECORDS`; such a
    record's ``calibration`` names its fold only, and its ``provenance`` the flight's
    checksum: the rest is its folder's :data:`RUN_RECORD` (:func:`read_run_record`)."""
    for d in folders:
        lines = Path(d) / INJECTED_RECORDS
        if lines.is_file():
            with lines.open() as f:
                yield from map(json.loads, f)
            continue
        for p in record_paths(d):
            yield json.loads(p.read_text())


def count_records(folder) -> int:
    """How many records a detections folder holds, without reading them."""
    lines = Path(folder) / INJECTED_RECORDS
    if lines.is_file():
        with lines.open("rb") as f:
            return sum(1 for _ in f)
    return len(record_paths(folder))


def read_run_record(folder) -> dict:
    """The :data:`RUN_RECORD` of an injected-detections folder: ``provenance`` (the
    run's, with each fold's calibration checksums) and ``folds`` (each fold's
    calibration block, as a real flight's record holds it)."""
    return json.loads((Path(folder) / RUN_RECORD).read_text())


def _referencing(record: dict, run: dict) -> dict:
    """``record`` with its calibration and provenance moved into ``run`` (the folder's
    :data:`RUN_RECORD`, filled here), keeping the fold's name and the flight's
    checksum."""
    cal, prov = record["calibration"], record["provenance"]
    if cal is not None:
        run["folds"][cal["fold"]] = cal
        run["calibration_sha256"][cal["fold"]] = prov["inputs"]["calibration_sha256"]
    if "provenance" not in run:
        run["provenance"] = {k: v for k, v in prov.items() if k != "inputs"}
    return {**record, "calibration": None if cal is None else {"fold": cal["fold"]},
            "provenance": {"flight_sha256": prov["inputs"]["flight_sha256"],
                           "run": RUN_RECORD}}


def read_failures(folders) -> list[pd.DataFrame]:
    """The ``failures.csv`` of each ``results/detections/{method}`` folder."""
    return [read_table(Path(d) / "failures.csv", dtype=str, keep_default_na=False)
            for d in folders]


def write_detections(method: str, spec: dict, flights: Mapping[str, Flight],
                     manifest: pd.DataFrame, calibration: dict, *, strict: bool, config: dict,
                     out: Path, traces: Path, panels: Path | None = None,
                     injected: tuple[pd.DataFrame, Path] | None = None) -> None:
    """Run :func:`detect_all` and write ``out/<flight>.json``, ``traces/<flight>.npz``
    and ``out/failures.csv`` (the flights excluded, empty when ``strict``, which
    raises instead), each with its provenance; with ``panels``, also its panel of
    each flight's figure there (:class:`~.figures.FlightPanel`, ``<flight>.png``).

    With ``injected`` (its manifest, and a folder), the injected flights of that
    manifest (in ``flights``) are scored in the same pass, each by the fit of its
    source's fold (one fit per fold for both), and their records and failures are
    written to the folder, without traces: a record holds all that is read of them.
    The records go to :data:`INJECTED_RECORDS`, a line each in the order of their
    flights' names. Their calibration blocks and provenance, the same for every flight
    of a fold, are written once, to the folder's :data:`RUN_RECORD`, which the records
    name.
    """
    extra, folder = injected if injected is not None else (manifest.iloc[:0], None)
    if panels is not None:
        from alfa_bench.outputs.flight_figures import (  # matplotlib: likewise
            FlightPanel,
            flight_span,
        )
        panel = FlightPanel(method)
        flight_s = dict(zip(manifest["flight"], manifest["flight_s"], strict=True))
    for path in (out, traces, panels, folder):
        if path is not None:
            path.mkdir(parents=True, exist_ok=True)
    failures = None if strict else []
    scored = pd.concat([manifest, extra], ignore_index=True) if len(extra) else manifest
    grid = set(extra["flight"])
    run = {"folds": {}, "calibration_sha256": {}}
    lines = {}
    for record, trace in detect_all(method, spec, flights, scored, calibration, failures,
                                    calibrate_on=manifest, stability=config.get("stability")):
        name = record["flight"]
        if name in grid:
            lines[name] = json.dumps(_referencing(record, run), sort_keys=True,
                                     allow_nan=False, default=list)
        else:
            write_record(record, out / f"{name}.json")
            write_trace(trace, traces / f"{name}.npz", record["provenance"])
            if panels is not None:
                panel.draw(trace, record["onset_s"], record["fault_end_s"],
                           flight_span(record["onset_s"], float(flight_s[name])),
                           panels / f"{name}.png")
        log.info("%s %s: %s, first alarm %s", method, name, record["outcome"],
                 record["first_alarm_s"])
    for where, rows, prov in [
            (out, [f for f in failures or [] if f["flight"] not in grid],
             run_provenance(config, manifest)),
            (folder, [f for f in failures or [] if f["flight"] in grid],
             run_provenance(config, extra, manifest))]:
        if where is not None:
            pd.DataFrame(rows, columns=FAILURE_COLUMNS).to_csv(where / "failures.csv",
                                                               index=False)
            stamp(where / "failures.csv", prov)
    if folder is not None:
        (folder / INJECTED_RECORDS).write_text("".join(lines[n] + "\n" for n in sorted(lines)))
        run.setdefault("provenance", provenance(spec, {}))   # no injected flight scored
        write_record(run, folder / RUN_RECORD)
