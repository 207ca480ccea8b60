"""What a result was made from: code version, packages, config, inputs, calibration.

Every result file records it (:func:`stamp`, :func:`read_provenance`): the project
version and git commit, the package versions, the configuration it was made with,
the SHA-256 of each input flight and the flights that calibrated each fold. The
record is deterministic (sorted keys, no times), so it does not break byte-identical
reruns.
"""

from __future__ import annotations

import ast
import importlib
import json
import struct
import subprocess
import zlib
from functools import cache
from importlib import metadata
from pathlib import Path

import numpy as np
import pandas as pd

from .calibration import folds

__all__ = ["PACKAGES", "code_version", "module_sources", "package_versions", "provenance",
           "read_provenance", "read_table", "run_provenance", "stamp"]

_CSV_PREFIX = "# provenance: "

PACKAGES = ("alfa-bench", "numpy", "scipy", "pandas", "filterpy", "control", "scikit-learn",
            "rerun-sdk", "snakemake", "matplotlib")


@cache
def code_version() -> dict:
    """Project version and git commit (None outside a checkout), and if the tree is dirty."""
    root = Path(__file__).resolve().parent.parent

    def git(*args):
        try:
            return subprocess.run(["git", "-C", str(root), *args], capture_output=True,
                                  text=True, check=True).stdout.strip()
        except (OSError, subprocess.CalledProcessError):
            return None

    commit = git("rev-parse", "HEAD")
    dirty = bool(git("status", "--porcelain", "--untracked-files=no")) if commit else None
    return {"version": metadata.version("alfa-bench"), "git_commit": commit, "git_dirty": dirty}


def module_sources(cls: type) -> list[str]:
    """The source files of the module defining ``cls`` and of every ``alfa_bench`` module
    it imports, transitively: the code a job that runs ``cls`` depends on. A workflow
    rule takes them as inputs, so that a changed module re-runs exactly the jobs of the
    detectors that use it. (``from . import x`` names the submodule ``x`` only, not its
    package: a detector added to the package's registry is no change to the others.)"""
    found: dict[str, str] = {}
    todo = [cls.__module__]
    while todo:
        name = todo.pop()
        if name not in found:
            found[name], imports = _imports(name)
            todo += imports
    return sorted(found.values())


@cache
def _imports(name: str) -> tuple[str, list[str]]:
    """The source file of module ``name`` and the ``alfa_bench`` modules it imports.
    Cached: the workflow asks once per method, and most share their modules."""
    module = importlib.import_module(name)
    found = []
    for node in ast.walk(ast.parse(Path(module.__file__).read_text())):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.startswith("alfa_bench")]
        elif isinstance(node, ast.ImportFrom):
            base = ("." * node.level + (node.module or "")) if node.level else node.module
            base = importlib.util.resolve_name(base, module.__package__)
            if not base.startswith("alfa_bench"):
                continue
            names = [] if node.module is None else [base]
            found += [m for m in (*names, *(f"{base}.{a.name}" for a in node.names))
                      if m == base or _is_module(m)]
    return module.__file__, found


def _is_module(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except ModuleNotFoundError:
        return False


@cache
def package_versions() -> dict:
    versions = {}
    for p in PACKAGES:
        try:
            versions[p] = metadata.version(p)
        except metadata.PackageNotFoundError:
            versions[p] = None
    return versions


def provenance(config: dict, inputs: dict, calibration: dict | None = None) -> dict:
    """The provenance block stored in every result file."""
    return {"code": code_version(), "packages": package_versions(), "config": config,
            "inputs": inputs, "calibration": calibration}


def run_provenance(config: dict, manifest: pd.DataFrame,
                   calibrate_on: pd.DataFrame | None = None) -> dict:
    """The provenance of a file made from every flight of ``manifest``: code, packages,
    the whole workflow ``config``, each flight's checksum and the calibration folds
    (which flights, of ``calibrate_on`` if given, calibrated each group's methods)."""
    cal = config.get("calibration")
    train = manifest if calibrate_on is None else calibrate_on
    sha = dict(zip(manifest["flight"], manifest["sha256"], strict=True))
    sha |= dict(zip(train["flight"], train["sha256"], strict=True))
    try:
        folds_ = {g: training for g, (_, training) in folds(train, cal["group_by"]).items()}
    except (TypeError, ValueError):     # no calibration configured, or under two groups
        folds_ = None
    return provenance(config, {"flight_sha256": sha},
                      calibration={**(cal or {}), "training_flights": folds_})


def _json(prov: dict) -> str:
    return json.dumps(prov, sort_keys=True, separators=(",", ":"), allow_nan=False)


def _png_text(data: bytes, key: str, text: str) -> bytes:
    """``data`` with a tEXt chunk ``key`` inserted after the IHDR chunk."""
    body = key.encode("latin-1") + b"\0" + text.encode("latin-1", "backslashreplace")
    chunk = (struct.pack(">I", len(body)) + b"tEXt" + body
             + struct.pack(">I", zlib.crc32(b"tEXt" + body)))
    end_of_ihdr = 8 + 8 + 13 + 4
    return data[:end_of_ihdr] + chunk + data[end_of_ihdr:]


def stamp(path: str | Path, prov: dict) -> None:
    """Record ``prov`` in the result file ``path``, in the way its format allows:
    a first ``# provenance: {json}`` line (.csv), a ``%`` line (.tex), an HTML
    comment (.md), a tEXt chunk (.png), a ``provenance.json`` member (.npz), a
    ``provenance`` key (.json). Rerun recordings carry it as a recording property
    (see :mod:`.rerun_log`), traces theirs as an array (see :mod:`.traces`)."""
    path = Path(path)
    text = _json(prov)
    match path.suffix:
        case ".csv":
            path.write_text(f"{_CSV_PREFIX}{text}\n" + path.read_text())
        case ".tex":
            path.write_text(f"% provenance: {text}\n" + path.read_text())
        case ".md":
            path.write_text(path.read_text() + f"\n<!-- provenance: {text} -->\n")
        case ".png":
            path.write_bytes(_png_text(path.read_bytes(), "provenance", text))
        case ".json":
            record = json.loads(path.read_text())
            path.write_text(json.dumps({**record, "provenance": prov}, sort_keys=True,
                                       indent=1, allow_nan=False) + "\n")
        case _:
            raise ValueError(f"cannot record provenance in {path}")


def read_provenance(path: str | Path) -> dict:
    """The provenance recorded in a result file (see :func:`stamp`)."""
    path = Path(path)
    match path.suffix:
        case ".csv" | ".tex":
            first = path.read_text().split("\n", 1)[0]
            return json.loads(first.split("provenance: ", 1)[1])
        case ".md":
            last = path.read_text().rstrip().rsplit("\n", 1)[-1]
            return json.loads(last.removeprefix("<!-- provenance: ").removesuffix(" -->"))
        case ".png":
            return json.loads(_png_chunks(path.read_bytes())[b"provenance"])
        case ".npz":
            with np.load(path) as z:
                return json.loads(str(z["provenance"][0]))
        case ".json":
            return json.loads(path.read_text())["provenance"]
        case ".rrd":
            from .rerun_log import read_rerun_provenance
            return read_rerun_provenance(path)
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
    """A result CSV, without its provenance line (``kwargs`` go to pandas)."""
    path = Path(path)
    with path.open() as f:
        skip = 1 if f.readline().startswith(_CSV_PREFIX) else 0
    return pd.read_csv(path, skiprows=skip, **kwargs)
