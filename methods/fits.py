r"""Fits kept in a process, keyed by the code, hyper-parameters and data that made them.

A fit is deterministic: the same detector code with the same hyper-parameters, fitted
on the same data, learns the same. Nested selection asks for the same fits again and
again (the out-of-sample maxima of its inner fit without date :math:`d` and of the one
without :math:`e` both need the model without :math:`\{d, e\}`, and later scored
dates' folds need the inner fits again), so fits are kept under a key of exactly those
three (:func:`fit_key`):

- the code: the class's module, qualified name and a digest of its source and of its
  bases' (:func:`~.base.source_digest`), so that a class of the same name in another
  module, or one redefined in a notebook, is another key;
- the hyper-parameters, as JSON: only plain data (:func:`plain_data`), since an
  estimator object may change after the fit;
- the data: the digest of every segment fitted on (:func:`~.base.segment_digest`), or
  any other JSON-ready description of it that names it exactly.

A key (:class:`FitKey`) is a digest of a JSON document of those, and carries it. Each
store (:class:`KeptFits`) keeps the fits last used in the process, up to its bound:
:data:`MODEL_FITS` the models :func:`kept_fit` fits, and
:data:`~.nested_selection.INNER_FITS` a nested selection's inner fits.

Once :func:`use_files` names a folder (the workflow's detect jobs name
``results/fits``), a fit not kept in the process is looked up there, and a fit made is
written there too (:class:`FitFiles`), so that the jobs of a run, later runs and
re-runs share it: one file per fit, ``<store>-<key>.npz``, in the model-file format
(:mod:`.model_files`: arrays and JSON, never pickle, a SHA-256 over all of it). The
file holds its key's whole document, and what else a fit depends on outside the
class: the source of every project module the class's module imports (the workflow
names them: :func:`~alfa_bench.workflow.dependencies.module_sources`; a helper edited
elsewhere is another key) and the versions of the package, Python and the numerical libraries. A
file whose document differs in any part, or whose digest fails, is refused (logged,
and fitted again). The folder is bounded (its total size): writing a fit evicts the
least recently used (a read touches its file). Files are written whole (a temporary
file in the folder, then renamed over the name), so two jobs that write the same fit
leave one whole file, and a reader sees an old file or a new one, never a part.

A fit whose learned state is not arrays and JSON (a library's estimator object: the
PyOD, scikit-learn and river models of :mod:`.outliers`, so the ``pyod_*`` and
``river_*`` runs and their nested twins; a :class:`~.base.CalibrationError` an inner
fit failed with) is kept in the process only.

Within :func:`fresh_fits` every store starts empty and the folder is neither read nor
written, and each store is given back its fits after: the contract's refit check fits
anew, so that a fit which is not deterministic cannot hide behind one kept before.
"""

from __future__ import annotations

import functools
import hashlib
import json
import logging
import os
import platform
import time
import weakref
from collections import Counter, OrderedDict
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

import numpy as np

from .base import Detector, learned_digest, segment_digest, source_digest
from .model_files import ModelFileError, decode, encode, read_archive, write_archive

__all__ = ["COUNTS", "MODEL_FITS", "FitFiles", "FitKey", "KeptFits", "code_of", "fit_key",
           "fresh_fits", "kept_fit", "plain_data", "segments_data", "use_files"]

log = logging.getLogger(__name__)

#: what the stores did in this process: fits ``made`` (fitted and put in a store),
#: ``kept`` (given again from the process), ``read`` (from the folder), ``refused``
#: (a file in the folder that did not match), ``unstorable`` (kept in the process
#: only), and the seconds ``reading_s`` and ``writing_s`` the folder's files
COUNTS: Counter = Counter()


def plain_data(value) -> bool:
    """Whether ``value`` is data alone (numbers, strings, None, and lists, tuples and
    string-keyed dicts of them), which JSON writes whole."""
    if value is None or isinstance(value, str | int | float | bool):
        return True
    if isinstance(value, list | tuple):
        return all(map(plain_data, value))
    if isinstance(value, dict):
        return all(isinstance(k, str) and plain_data(v) for k, v in value.items())
    return False


@functools.cache
def code_of(cls: type) -> dict[str, str]:
    """What names the code of ``cls``: its module, qualified name and the digest of its
    source and its bases', alfa-bench's included (read once per class: a class object
    runs the code it was made from, whatever its file says later)."""
    return {"module": cls.__module__, "class": cls.__qualname__,
            "source": source_digest(cls, package=True)}


def segments_data(segments: list) -> list[str]:
    """The data of ``segments`` as a key names it: each one's
    :func:`~.base.segment_digest`, in order."""
    return [segment_digest(s).hex() for s in segments]


class FitKey(str):
    """A fit's key: the digest of its ``document`` (the code, hyper-parameters and data
    that name the fit), which it carries for the folder's files to record and check.

    Parameters
    ----------
    document : dict
        JSON-ready.
    """

    document: dict

    def __new__(cls, document: dict) -> FitKey:
        key = super().__new__(cls, hashlib.blake2b(json.dumps(document, sort_keys=True)
                                                   .encode(), digest_size=16).hexdigest())
        key.document = document
        return key


def fit_key(detector: Detector, data, params: dict | None = None) -> FitKey | None:
    """The key of a fit of ``detector``'s code with ``params`` (default: all its
    hyper-parameters) on ``data`` (JSON-ready, such as :func:`segments_data`); None
    where the hyper-parameters are not plain data (such a fit is not kept)."""
    params = detector.get_params() if params is None else params
    if not plain_data(params):
        return None
    return FitKey({**code_of(type(detector)), "params": params, "data": data})


@functools.cache
def _versions() -> dict[str, str]:
    """What else a fit may depend on: the versions of the package, Python and the
    numerical libraries (as installed: importing one costs more than a fit)."""
    from alfa_bench import __version__

    return {"alfa-bench": __version__, "python": platform.python_version(),
            **{name: metadata.version(name) for name in ("numpy", "scipy", "scikit-learn",
                                                         "numba")}}


class FitFiles:
    """Fits on disk: one file per fit in ``folder``, at most ``max_bytes`` in all, the
    least recently used evicted first (module docstring).

    Parameters
    ----------
    folder : str or path-like
        Made when the first fit is written.
    max_bytes : int
        The bound on the folder's total size.
    sources : callable
        The source files a module's code runs on, by the module's name (the module's
        own and those of the project's modules it imports): a fit's file records their
        digest.
    """

    #: the format's name, in every file
    FORMAT = "alfa-bench fit"
    #: the version of what a file holds
    FORMAT_VERSION = 1

    def __init__(self, folder: str | os.PathLike, max_bytes: int,
                 sources: Callable[[str], list[str]]):
        self.folder = Path(folder)
        self.max_bytes = max_bytes
        self.sources = sources
        #: the folder's size as last seen, plus what this process wrote since
        self._size: int | None = None
        self._modules: dict[str, str | None] = {}

    def path(self, store: str, key: FitKey) -> Path:
        """The file of the fit under ``key`` in ``store``."""
        return self.folder / f"{store}-{key}.npz"

    def _document(self, store: str, key: FitKey) -> dict | None:
        """All a file must match, as JSON reads it back (a tuple as a list): the store,
        the key's document, the code of the project's modules it reads, the versions
        (:func:`_versions`); None where the class's module has no source to digest (not
        written then)."""
        modules = self._modules_digest(key.document["module"])
        if modules is None:
            return None
        return json.loads(json.dumps({"store": store, "key": key.document,
                                      "modules": modules, "versions": _versions()}))

    def _modules_digest(self, module: str) -> str | None:
        """A digest of the :attr:`sources` of ``module`` (read once: a module runs the
        code it was imported from); None for a module without a file (a notebook's,
        ``__main__`` run from a string)."""
        if module not in self._modules:
            try:
                paths = self.sources(module)
            except (ImportError, ValueError, TypeError, OSError):   # no module file
                paths = None
            h = hashlib.sha256()
            for path in paths or ():
                h.update(Path(path).name.encode() + b"\0" + Path(path).read_bytes())
            self._modules[module] = None if paths is None else h.hexdigest()
        return self._modules[module]

    def read(self, store: str, key: FitKey):
        """The fit under ``key`` in ``store``, its file touched (now the last used); None
        where there is none, or the file is refused: damaged, or written for another
        document (each refusal logged)."""
        document = self._document(store, key)
        path = self.path(store, key)
        if document is None or not path.is_file():
            return None
        try:
            body, arrays = read_archive(path)
            if body.get("format") != self.FORMAT or body.get(
                    "format_version") != self.FORMAT_VERSION:
                raise ModelFileError(f"{path}: not a file of {self.FORMAT!r} version "
                                     f"{self.FORMAT_VERSION}")
            if body["document"] != document:
                differ = sorted(k for k in document if body["document"].get(k) != document[k])
                raise ModelFileError(f"{path}: written for another {', '.join(differ)}")
            changed: list[str] = []
            fit = decode(body["fit"], arrays, changed)
            if changed or (isinstance(fit, Detector) and learned_digest(fit) != getattr(
                    fit, "fit_digest_", None)):
                raise ModelFileError(f"{path}: the state read is not the fit written")
            os.utime(path)
        except (ModelFileError, KeyError, TypeError, ValueError, OSError) as e:
            if not path.is_file():         # evicted by another job since
                return None
            log.warning("fit refused, fitted again: %s", e)
            COUNTS["refused"] += 1
            return None
        return fit

    def write(self, store: str, key: FitKey, fit) -> bool:
        """Write ``fit`` under ``key`` in ``store``, whole (a temporary file renamed over
        the name), then evict the least recently used beyond the bound. False, and
        nothing written, where the fit is not arrays and JSON or its class's module has
        no source."""
        document = self._document(store, key)
        if document is None or isinstance(fit, BaseException):
            return False
        arrays: list[np.ndarray] = []
        try:
            body = {"format": self.FORMAT, "format_version": self.FORMAT_VERSION,
                    "document": document, "fit": encode(fit, arrays, "fit")}
        except (ModelFileError, KeyError) as e:
            log.debug("fit kept in the process only: %s", e)
            return False
        self.folder.mkdir(parents=True, exist_ok=True)
        path = self.path(store, key)
        part = path.with_name(f".{path.name}.{os.getpid()}.part")
        try:
            write_archive(part, body, arrays)
            part.replace(path)
        except OSError as e:              # a full disk: the fit stays in the process
            log.warning("fit not written to %s: %s", self.folder, e)
            part.unlink(missing_ok=True)
            return True
        if self._size is None:
            self._size = self._files()[1]
        else:
            self._size += path.stat().st_size
        if self._size > self.max_bytes:
            self.evict()
        return True

    def _files(self) -> tuple[list[tuple[float, int, Path]], int]:
        """The folder's files, least recently used first (mtime, size, path), and their
        total size."""
        found = []
        with os.scandir(self.folder) as entries:
            for e in entries:
                try:
                    st = e.stat()
                except FileNotFoundError:
                    continue
                found.append((st.st_mtime, st.st_size, Path(e.path)))
        found.sort()
        return found, sum(size for _, size, _ in found)

    def evict(self) -> None:
        """Remove the least recently used files until the folder holds at most nine
        tenths of the bound (a margin, so that a job near it does not list the folder
        on each write)."""
        found, size = self._files()
        for _, bytes_, path in found:
            if size <= 0.9 * self.max_bytes:
                break
            path.unlink(missing_ok=True)
            size -= bytes_
        self._size = size


#: the folder :class:`KeptFits` reads and writes (:func:`use_files`), None for none
_FILES: FitFiles | None = None


def use_files(folder: str | os.PathLike | None, max_bytes: int = 0,
              sources: Callable[[str], list[str]] | None = None) -> None:
    """Keep this process's fits in ``folder`` too (:class:`FitFiles`, with
    ``max_bytes`` and ``sources``, which it needs); None: in the process only."""
    global _FILES
    if folder is not None and sources is None:
        raise ValueError("use_files: a folder of fits needs the sources of the modules "
                         "their code runs on")
    _FILES = None if folder is None else FitFiles(folder, max_bytes, sources)


class KeptFits:
    """Fits by their key (:func:`fit_key`), the ``kept`` last used; with a ``name``, also
    in the folder :func:`use_files` names.

    Parameters
    ----------
    kept : int
        How many fits are kept in the process; the least recently used goes first.
    name : str, optional
        The store's name in the folder's file names, apart from every other store's
        (whose fits under the same key are other things); None: in the process only.
    counted : bool
        Whether what it makes and gives again counts in :data:`COUNTS`: a store of
        fits; not a store of what fits share (the logistic classifiers' designs), which
        the cost table would count as fits.
    """

    def __init__(self, kept: int, name: str | None = None, counted: bool = True):
        self.kept = kept
        self.name = name
        self.counted = counted
        self._fits: OrderedDict[str, object] = OrderedDict()
        _STORES.add(self)

    def __len__(self) -> int:
        return len(self._fits)

    def _files(self, key) -> FitFiles | None:
        """The folder to read and write ``key``'s fit in, if any: a named store's, under
        a key that carries its document."""
        return _FILES if self.name is not None and isinstance(key, FitKey) else None

    def get(self, key: str | None):
        """The fit kept under ``key``, now the last used, else the fit in the folder
        (:func:`use_files`), now kept; None where there is none (or ``key`` is None)."""
        if key is None:
            return None
        if key in self._fits:
            self._fits.move_to_end(key)
            COUNTS["kept"] += self.counted
            return self._fits[key]
        files = self._files(key)
        if files is None:
            return None
        started = time.perf_counter()
        fit = files.read(self.name, key)
        COUNTS["reading_s"] += time.perf_counter() - started
        if fit is not None:
            COUNTS["read"] += 1
            self._keep(key, fit)
        return fit

    def put(self, key: str | None, fit) -> None:
        """Keep ``fit``, just made, under ``key`` (not where ``key`` is None), dropping
        the least recently used beyond :attr:`kept`; and write it to the folder."""
        if key is None:
            return
        COUNTS["made"] += self.counted
        self._keep(key, fit)
        files = self._files(key)
        if files is not None:
            started = time.perf_counter()
            COUNTS["unstorable"] += not files.write(self.name, key, fit)
            COUNTS["writing_s"] += time.perf_counter() - started

    def _keep(self, key: str, fit) -> None:
        self._fits[key] = fit
        self._fits.move_to_end(key)
        while len(self._fits) > self.kept:
            self._fits.popitem(last=False)

    def clear(self) -> None:
        """Forget every fit."""
        self._fits.clear()


#: every store, for :func:`fresh_fits`
_STORES: weakref.WeakSet[KeptFits] = weakref.WeakSet()


@contextmanager
def fresh_fits() -> Iterator[None]:
    """Within it, every :class:`KeptFits` starts empty and the folder
    (:func:`use_files`) is neither read nor written, so that a fit is made anew, not
    taken from one made before; the fits made within may serve each other, as in any
    fit. After it, each store holds what it held before, and none made within."""
    global _FILES
    held = [(store, store._fits) for store in list(_STORES)]
    files, _FILES = _FILES, None
    for store, _ in held:
        store._fits = OrderedDict()
    try:
        yield
    finally:
        _FILES = files
        for store, fits in held:
            store._fits = fits


#: the models :func:`kept_fit` fitted in this process, each as the attributes its fit
#: set: the 256 last used (and in the folder, :func:`use_files`)
MODEL_FITS = KeptFits(256, "model")


def kept_fit(detector: Detector, segments: list, fit, state: tuple[str, ...]) -> None:
    """``fit(segments)``, which sets ``detector``'s learned attributes ``state``, or
    those attributes as a fit of the same code with the same hyper-parameters (the
    threshold's aside: :attr:`~.base.Detector.threshold_params`) on the same data left
    them, kept in :data:`MODEL_FITS` (in the process, and in the folder
    :func:`use_files` names where the state is arrays and JSON).

    Only a detector whose hyper-parameters are plain data (:func:`plain_data`) is kept.
    A kept fit is restored in the order the fit set its attributes, as the fit token
    (:func:`~.base.fit_token`) digests them in order."""
    params = {k: v for k, v in detector.get_params().items()
              if k not in detector.threshold_params}
    key = fit_key(detector, segments_data(segments), params)
    kept = MODEL_FITS.get(key)
    if kept is not None:
        detector.__dict__.update(kept)
        return
    fit(segments)
    MODEL_FITS.put(key, {n: v for n, v in vars(detector).items() if n in state})
