"""A fitted detector in one file that loads without running any code from it.

A model file is a NumPy ``.npz`` archive (a zip) of plain arrays: ``model.json``, a
JSON document as bytes, and ``a0``, ``a1``, ... the numeric arrays it refers to. The
document holds the format's name and version, the package version that wrote it, the
run's name and config, the digests of the data it was fitted on, the signals the
detector reads (at which grid rate, and whether one is written by ALFA's fault
emulation), its registry name and hyper-parameters, and its learned state (every
attribute ending in ``_``, :func:`~.base.learned_state`) encoded as

- numbers, strings, booleans and None as JSON, a non-finite float as
  ``{"float": "nan"}``;
- lists as JSON lists, tuples as ``{"tuple": [...]}``, string-keyed dicts as
  ``{"dict": {...}}``, other keys as ``{"pairs": [[key, value], ...]}``;
- a numeric array or NumPy scalar as ``{"array": i}`` (``a<i>`` in the archive);
- a detector held by another (a nested selection's base, a classifier's residual bank)
  as ``{"detector": name, "params": ..., "state": ..., "source": ...}``, built again
  from the registry.

Each detector, the saved one and those it holds, records the digest of its class's
code (``source``: :func:`~.base.source_digest`, alfa-bench's own bases included).

Anything else (a library's estimator object, an object array) is refused when saving,
naming the attribute. Loading reads the archive with ``allow_pickle=False``, checks a
SHA-256 over the document and every array, the format and the package version, builds
the detector from the registry by name, sets its learned state (names ending in ``_``
only) and checks that its fit token is the one saved: the detector is the fitted one,
by value, or the load fails. A detector whose code here is not the code that fitted
it (its class edited since, within the same package version) is said so in a
warning, naming it, and in what :func:`load_model` returns (``code_changed``): it
loads, since its state is the one saved, but what it scores may differ. The digests
are in the file: they catch a damaged file or an edit that did not recompute them,
not a forger; what holds against any file is that loading runs none of its code.

The encoding (:func:`encode`, :func:`decode`) and the checked archive
(:func:`write_archive`, :func:`read_archive`) also hold the fits kept on disk
(:mod:`.fits`).
"""

from __future__ import annotations

import hashlib
import io
import json
import logging
import math
import os
import zipfile
import zlib
from collections import deque
from pathlib import Path

import numpy as np

from alfa_bench.data import reads_actuators

from .base import Detector, fit_token, learned_digest, learned_state, source_digest

__all__ = ["FORMAT", "FORMAT_VERSION", "ModelFileError", "decode", "encode", "load_model",
           "read_archive", "save_model", "write_archive"]

log = logging.getLogger(__name__)

#: the format's name, in every file
FORMAT = "alfa-bench model"
#: the version of the encoding (module docstring)
FORMAT_VERSION = 1


class ModelFileError(ValueError):
    """A model file that cannot be written or loaded: the message names the file and what
    is wrong."""


def _version() -> str:
    from alfa_bench import __version__

    return __version__


def encode(value, arrays: list[np.ndarray], where: str):
    """``value`` as JSON-ready data (module docstring), its numeric arrays appended to
    ``arrays`` and named by their index; raises :class:`ModelFileError` naming
    ``where`` in it for what cannot be saved as arrays and JSON."""
    from . import detector_name

    if isinstance(value, Detector):
        return {"detector": detector_name(value), "params": encode(value.get_params(), arrays,
                                                                    f"{where}.params"),
                "state": encode(learned_state(value), arrays, f"{where}.state"),
                "source": source_digest(type(value), package=True)}
    if isinstance(value, np.ndarray | np.generic):
        a = np.asarray(value)
        if a.dtype.hasobject or a.dtype.kind not in "biufc":
            raise ModelFileError(f"{where}: an array of {a.dtype} cannot be saved")
        arrays.append(a)
        return {"array": len(arrays) - 1}
    if isinstance(value, bool) or value is None or isinstance(value, str | int):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else {"float": repr(value)}
    if isinstance(value, list):
        return [encode(v, arrays, f"{where}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, tuple):
        return {"tuple": [encode(v, arrays, f"{where}[{i}]") for i, v in enumerate(value)]}
    if isinstance(value, deque):
        return {"deque": [encode(v, arrays, f"{where}[{i}]") for i, v in enumerate(value)],
                "maxlen": value.maxlen}
    if isinstance(value, dict):
        if all(isinstance(k, str) for k in value):
            return {"dict": {k: encode(v, arrays, f"{where}.{k}") for k, v in value.items()}}
        return {"pairs": [[encode(k, arrays, f"{where} key"),
                           encode(v, arrays, f"{where}[{k!r}]")] for k, v in value.items()]}
    raise ModelFileError(f"{where}: a {type(value).__name__} cannot be saved as arrays and "
                         "JSON")


def decode(value, arrays: dict[str, np.ndarray], changed: list[str]):
    """``value`` as :func:`encode` wrote it (its arrays named ``a<i>``), decoded; the
    name of each detector built whose code is not the code saved is appended to
    ``changed``."""
    if isinstance(value, list):
        return [decode(v, arrays, changed) for v in value]
    if not isinstance(value, dict):
        return value
    if "array" in value:
        a = arrays[f"a{value['array']}"]
        return a[()] if a.ndim == 0 else a
    if "float" in value:
        return float(value["float"])
    if "tuple" in value:
        return tuple(decode(v, arrays, changed) for v in value["tuple"])
    if "deque" in value:
        return deque((decode(v, arrays, changed) for v in value["deque"]),
                     maxlen=value["maxlen"])
    if "dict" in value:
        return {k: decode(v, arrays, changed) for k, v in value["dict"].items()}
    if "pairs" in value:
        return {decode(k, arrays, changed): decode(v, arrays, changed)
                for k, v in value["pairs"]}
    if "detector" in value:
        return _build(value, arrays, changed)
    raise ValueError(f"unknown encoding {sorted(value)}")


def _build(spec: dict, arrays: dict[str, np.ndarray], changed: list[str]) -> Detector:
    from . import make_detector

    detector = make_detector(spec["detector"], decode(spec["params"], arrays, changed))
    if spec.get("source") != source_digest(type(detector), package=True):
        changed.append(spec["detector"])
    for name, v in decode(spec["state"], arrays, changed).items():
        if not name.endswith("_") or name.startswith("_"):
            raise ValueError(f"{name!r} is not a learned attribute")
        setattr(detector, name, v)
    return detector


def write_archive(path: str | os.PathLike, body: dict, arrays: list[np.ndarray]) -> Path:
    """Write ``body`` (JSON-ready, as :func:`encode` gives) and the ``arrays`` it refers
    to as an archive at ``path``: ``model.json``, ``a0``, ``a1``, ... and the SHA-256
    over them (``sha256``), as :func:`numpy.savez_compressed` writes them but dated
    1980-01-01, so that the same content is the same bytes."""
    # keys in their order: a restored state must be set in the order the fit set it
    document = json.dumps(body, allow_nan=False).encode()
    named = {f"a{i}": a for i, a in enumerate(arrays)}
    digest = _digest(document, named)
    path = Path(path)
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, a in {**named, "model.json": np.frombuffer(document, np.uint8),
                        "sha256": np.frombuffer(digest.encode(), np.uint8)}.items():
            member = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            member.compress_type = zipfile.ZIP_DEFLATED
            with archive.open(member, "w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asanyarray(a), allow_pickle=False)
    path.write_bytes(buffer.getvalue())
    return path


def read_archive(path: str | os.PathLike) -> tuple[dict, dict[str, np.ndarray]]:
    """The document and the arrays (``a<i>``) of the archive at ``path``
    (:func:`write_archive`), read without pickle and checked against their SHA-256.

    Raises
    ------
    ModelFileError
        Naming the file: unreadable, not such an archive, or damaged or altered."""
    try:
        with np.load(path, allow_pickle=False) as archive:
            arrays = {name: archive[name] for name in archive.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError, zlib.error) as e:
        raise ModelFileError(f"{path}: not a readable model file ({e})") from None
    try:
        document = arrays.pop("model.json").tobytes()
        saved = arrays.pop("sha256").tobytes().decode()
    except (KeyError, UnicodeDecodeError):
        raise ModelFileError(f"{path}: not an alfa-bench model file") from None
    if _digest(document, arrays) != saved:
        raise ModelFileError(f"{path}: its content does not match its SHA-256: the file is "
                             "damaged or was edited")
    return json.loads(document), arrays


def _digest(document: bytes, arrays: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256(document)
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(f"{name}<{a.dtype.str}{a.shape}>".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def save_model(detector: Detector, path: str | os.PathLike, *, run: str,
               config: dict | None = None, data: dict | None = None) -> Path:
    """Write the fitted ``detector`` to ``path``: the run's name, its ``config`` spec and
    the ``data`` it was fitted on (flight -> SHA-256) beside its state (module
    docstring). Raises :class:`ModelFileError` naming an attribute that cannot be saved."""
    detector._check_fitted("fit_digest_")
    if learned_digest(detector) != detector.fit_digest_:
        raise ModelFileError(f"{type(detector).__name__} has run or changed since its fit: "
                             "save it right after fit()")
    arrays: list[np.ndarray] = []
    body = {"format": FORMAT, "format_version": FORMAT_VERSION, "version": _version(),
            "run": run, "config": config or {}, "data": data or {},
            "signals": list(detector.signals()), "rate_hz": detector.rate_hz,
            "reads_actuators": reads_actuators(detector.signals()),
            "fit_token": fit_token(detector),
            "model": encode(detector, arrays, type(detector).__name__)}
    return write_archive(path, body, arrays)


def load_model(path: str | os.PathLike) -> tuple[Detector, dict]:
    """The fitted detector of the model file ``path``, and what the file says of it (its
    run, config, data, version, and ``code_changed``: the detectors, by registry name,
    whose code differs from the code that fitted them, also said in a warning). Nothing
    in the file is run: arrays are read without pickle, the detector is built by its
    registry name.

    Raises
    ------
    ModelFileError
        Naming the file: not a model file, damaged or altered (its SHA-256), of another
        format or package version, of a detector this installation does not know, or a
        state that does not give the saved fit."""
    path = Path(path)
    body, arrays = read_archive(path)
    if body.get("format") != FORMAT or body.get("format_version") != FORMAT_VERSION:
        raise ModelFileError(f"{path}: format {body.get('format')!r} version "
                             f"{body.get('format_version')!r}; this reads {FORMAT!r} "
                             f"version {FORMAT_VERSION}")
    if body["version"] != _version():
        raise ModelFileError(f"{path}: written by alfa-bench {body['version']}, this is "
                             f"{_version()}: fit the run again with this version")
    changed: list[str] = []
    try:
        detector = _build(body["model"], arrays, changed)
    except KeyError as e:
        raise ModelFileError(f"{path}: detector {body['model'].get('detector')!r} is not "
                             f"registered here ({e})") from None
    except (TypeError, ValueError) as e:
        raise ModelFileError(f"{path}: its detector cannot be built ({e})") from None
    if learned_digest(detector) != detector.fit_digest_ or fit_token(detector) != body[
            "fit_token"]:
        raise ModelFileError(f"{path}: the state loaded does not give the fit saved")
    if changed:
        log.warning("%s: the code of %s is not the code that fitted it (edited since): "
                    "it loads, but may score otherwise; fit the run again to be sure",
                    path, ", ".join(dict.fromkeys(changed)))
    return detector, {**{k: v for k, v in body.items() if k != "model"},
                      "code_changed": list(dict.fromkeys(changed))}
