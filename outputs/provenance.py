"""What a result was made from, written beside it: stamps, the run file, and reading them.

A provenance block (:func:`alfa_bench.analysis.provenance.provenance`) holds the
project version and git commit, the package versions, the configuration (with where
the flights came from), the SHA-256 of each input flight and the flights that
calibrated each fold. It is deterministic (sorted keys,
no times), so it does not break byte-identical reruns.

The run's block is written once, to :data:`RUN_FILE` (:func:`write_run_file`), with
the SHA-256 of every output, so that tables stay plain: a CSV is RFC 4180 with its
header on line 1, and a Markdown or LaTeX table ends with one short line naming the
run (:func:`run_id`) and that file. Files that can carry metadata without getting in a
reader's way carry their own block (:func:`stamp`): figures, traces, detection
records, Parquet tables, recordings. :func:`read_provenance` reads either kind.
"""

from __future__ import annotations

import hashlib
import json
import struct
import zlib
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["RUN_FILE", "file_sha256", "read_provenance", "read_table", "run_id", "stamp",
           "write_run_file"]

#: where the run's provenance and every output's checksum are written
RUN_FILE = "results/provenance.json"


def _json(prov: dict) -> str:
    return json.dumps(prov, sort_keys=True, separators=(",", ":"), allow_nan=False)


def _png_text(data: bytes, key: str, text: str) -> bytes:
    """``data`` with a tEXt chunk ``key`` inserted after the IHDR chunk."""
    body = key.encode("latin-1") + b"\0" + text.encode("latin-1", "backslashreplace")
    chunk = (struct.pack(">I", len(body)) + b"tEXt" + body
             + struct.pack(">I", zlib.crc32(b"tEXt" + body)))
    end_of_ihdr = 8 + 8 + 13 + 4
    return data[:end_of_ihdr] + chunk + data[end_of_ihdr:]


def run_id(prov: dict) -> str:
    """A short name of the run ``prov`` comes from: 12 digits of the SHA-256 of its code,
    packages and config (which names where the flights came from), the same for every
    file of the run whatever flights it was made of."""
    run = {k: prov.get(k) for k in ("code", "packages", "config")}
    return hashlib.sha256(_json(run).encode()).hexdigest()[:12]


def file_sha256(path: str | Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def stamp(path: str | Path, prov: dict) -> None:
    """Record ``prov`` with the result file ``path``, in the way its format allows.
    A CSV is left plain: :data:`RUN_FILE` holds its run's block and its checksum. A
    Markdown or HTML page ends with one line naming the run and that file, a LaTeX
    file starts with one as a comment. A PNG gets a tEXt chunk, a ``.json`` record a
    ``provenance`` key. Rerun recordings carry it as a recording property (see
    :mod:`.rerun_log`), traces theirs as an array (see :mod:`.traces`), Parquet tables
    in their schema's metadata (see :mod:`.parquet`)."""
    path = Path(path)
    text = _json(prov)
    match path.suffix:
        case ".csv":
            pass
        case ".tex":
            path.write_text(f"% run {run_id(prov)}; its provenance: {RUN_FILE}\n"
                            + path.read_text())
        case ".md":
            path.write_text(path.read_text() + f"\n*Run `{run_id(prov)}`: code, packages, "
                            f"config, data and checksums in `{RUN_FILE}`.*\n")
        case ".html":
            path.write_text(path.read_text().replace("</body>", (
                f"<p><em>Run <code>{run_id(prov)}</code>: code, packages, config, data and "
                f"checksums in <code>{RUN_FILE}</code>.</em></p>\n</body>"), 1))
        case ".png":
            path.write_bytes(_png_text(path.read_bytes(), "provenance", text))
        case ".json":
            record = json.loads(path.read_text())
            path.write_text(json.dumps({**record, "provenance": prov}, sort_keys=True,
                                       indent=1, allow_nan=False) + "\n")
        case _:
            raise ValueError(f"cannot record provenance in {path}")


def write_run_file(path: str | Path, prov: dict, outputs, root: str | Path = ".",
                   unchecked=()) -> None:
    """Write the run's block ``prov`` to ``path`` with the SHA-256 of every file of
    ``outputs`` (files or folders, under ``root``), by its path from ``root``; the
    files matching a glob of ``unchecked`` are listed with no checksum (what differs
    between runs by nature: clock-drawn ids, measured times)."""
    root = Path(root)
    files = sorted({f for o in map(Path, outputs) for f in
                    ([o] if o.is_file() else (p for p in o.rglob("*") if p.is_file()))})
    sums = {}
    for f in files:
        rel = f.resolve().relative_to(root.resolve()).as_posix()
        sums[rel] = (None if any(Path(rel).match(g) for g in unchecked)
                     else file_sha256(f))
    Path(path).write_text(json.dumps({"run_id": run_id(prov), "run": prov,
                                      "outputs": sums, "unchecked": list(unchecked)},
                                     sort_keys=True, indent=1, allow_nan=False) + "\n")


def _run_file_of(path: Path) -> tuple[dict, str]:
    """The run file that lists ``path``, and ``path`` as it is named there."""
    for root in path.resolve().parents:
        run = root / RUN_FILE
        if run.is_file():
            return json.loads(run.read_text()), path.resolve().relative_to(root).as_posix()
    raise ValueError(f"no {RUN_FILE} above {path}: it was not written by a whole run")


def read_provenance(path: str | Path) -> dict:
    """The provenance of a result file: its own (see :func:`stamp`), or for a CSV,
    Markdown, HTML or LaTeX table that of the run file listing it, whose checksum it must
    still match where one is recorded. The injected flights' records (``.jsonl``) name
    the run record of their folder, which holds the rest
    (``analysis.detections.RUN_RECORD``): their provenance is the run's, with every
    flight's checksum and those of every fold's calibration flights."""
    path = Path(path)
    match path.suffix:
        case ".csv" | ".tex" | ".md" | ".html":
            run, name = _run_file_of(path)
            if name not in run["outputs"]:
                raise ValueError(f"{path} is not among the outputs of the run in {RUN_FILE}")
            recorded = run["outputs"][name]
            # an output that differs between runs by nature is listed without a checksum
            if recorded is not None and recorded != file_sha256(path):
                raise ValueError(f"{path} is no longer the file its run recorded in {RUN_FILE}")
            return run["run"]
        case ".parquet":
            import pyarrow.parquet as pq
            return json.loads(pq.read_schema(path).metadata[b"provenance"])
        case ".png":
            return json.loads(_png_chunks(path.read_bytes())[b"provenance"])
        case ".npz":
            with np.load(path) as z:
                return json.loads(str(z["provenance"][0]))
        case ".json":
            return json.loads(path.read_text())["provenance"]
        case ".jsonl":
            # injected flights' records: the run's provenance is their folder's run
            # record; each names its flight's checksum, and its fold's calibration there
            with path.open() as f:
                records = [json.loads(line) for line in f]
            runs = {r["provenance"]["run"] for r in records}
            if len(runs) != 1:
                raise ValueError(f"{path}: its records name {len(runs)} run records, not one")
            run = json.loads((path.parent / runs.pop()).read_text())
            return {**run["provenance"], "inputs": {
                "flight_sha256": {r["flight"]: r["provenance"]["flight_sha256"]
                                  for r in records},
                "calibration_sha256": {f: sha for fold in run["calibration_sha256"].values()
                                       for f, sha in fold.items()}}}
        case ".rrd":       # the recording's property (rerun_log.write_rerun_log)
            import rerun.chunk as rc
            for chunk in rc.RrdReader(path).store().stream().to_chunks():
                if chunk.entity_path == "/__properties/provenance":
                    return json.loads(chunk.to_record_batch().column("json").to_pylist()[0][0])
            raise ValueError(f"{path} carries no provenance property")
    raise ValueError(f"no provenance is recorded in {path}")


def _png_chunks(data: bytes) -> dict[bytes, str]:
    out, pos = {}, 8
    while pos < len(data):
        (n,) = struct.unpack_from(">I", data, pos)
        kind = data[pos + 4:pos + 8]
        if kind == b"tEXt":
            key, _, value = data[pos + 8:pos + 8 + n].partition(b"\0")
            out[key] = value.decode("latin-1")
        pos += 12 + n
    return out


def read_table(path: str | Path, **kwargs) -> pd.DataFrame:
    """A result CSV (``kwargs`` go to pandas): plain, as any tool reads it."""
    return pd.read_csv(path, **kwargs)
