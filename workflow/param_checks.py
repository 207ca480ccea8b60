"""The config's checks of each run's parameters, kept between runs of the workflow.

The process that plans a run checks every config run before any job
(:meth:`~alfa_bench.methods.base.Detector.check_params`); a PyOD or river run's check
builds its model, which imports the library and scikit-learn: 1.4 s of each
``snakemake`` start. A check that passed is kept in the working directory's
``.snakemake`` folder (:data:`KEPT`), keyed by the run's detector and parameters, the
source of the detectors and the data layer (every file of ``alfa_bench.methods`` and
``alfa_bench.data``), Python's version and every distribution installed (a check may
import any library, and a model may need one alfa-bench does not install): the same
key gives the same check, so it is not made again. A failed check is never kept, nor
one of an installed plugin's detector or with keys JSON cannot order; a file that
cannot be read is checked anew and written again, and one that cannot be written is
named in a warning, the run going on.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import platform
import sys
import tempfile
from collections.abc import Callable
from functools import cache
from pathlib import Path

__all__ = ["KEPT", "KeptChecks", "run_key"]

#: where the passed checks are kept, in the working directory
KEPT = Path(".snakemake/alfa-bench/param-checks.json")


def _installed() -> list[str]:
    """Every distribution installed where this Python imports from, by its metadata
    folder's name (name and version), so that one installed or removed checks again.
    Listing the folders costs milliseconds; reading each one's metadata, a fifth of a
    second."""
    names = set()
    for entry in sys.path:
        try:
            names.update(n for n in os.listdir(entry or ".")
                         if n.endswith((".dist-info", ".egg-info")))
        except OSError:        # a zip, or a folder that is not there
            continue
    return sorted(names)


@cache
def _code_and_versions() -> str:
    import alfa_bench.data
    import alfa_bench.methods

    h = hashlib.sha256()
    for package in (alfa_bench.methods, alfa_bench.data):
        for folder in package.__path__:
            for path in sorted(Path(folder).rglob("*.py")):
                h.update(f"{package.__name__}/{path.relative_to(folder)}\0".encode())
                h.update(path.read_bytes())
    h.update(json.dumps([platform.python_version(), _installed()]).encode())
    return h.hexdigest()


def run_key(spec: dict) -> str | None:
    """The key of a config run's check: its detector and parameters, the code and the
    versions (module docstring); None for a run of an installed plugin's detector (or
    a nested selection over one), whose source is not alfa-bench's, and for parameters
    whose keys JSON cannot order: their check is made every time."""
    from alfa_bench.methods import BUILTIN_ENTRIES

    named = [spec["detector"], (spec.get("params") or {}).get("detector")]
    if any(n not in BUILTIN_ENTRIES for n in named if n is not None):
        return None
    document = {"detector": spec["detector"], "params": spec.get("params"),
                "code": _code_and_versions()}
    try:
        text = json.dumps(document, sort_keys=True, default=repr)
    except (TypeError, ValueError):       # keys such as 1 beside "p"
        return None
    return hashlib.sha256(text.encode()).hexdigest()


class KeptChecks:
    """The passed checks of the working directory (:data:`KEPT`): :meth:`check` each
    config run, then :meth:`save`.

    Parameters
    ----------
    path : path
        The file they are kept in.
    """

    def __init__(self, path: str | os.PathLike = KEPT):
        self.path = Path(path)
        try:
            # a regular file only: a folder or a pipe in its place is not read
            keys = json.loads(self.path.read_text()) if self.path.is_file() else []
        except (OSError, ValueError, RecursionError):    # unreadable: checked anew
            keys = []
        self.kept_ = ({k for k in keys if isinstance(k, str)} if isinstance(keys, list)
                      else set())
        self.passed_: set[str] = set()
        self.made_ = 0

    def check(self, spec: dict, check: Callable[[], None]) -> None:
        """Call ``check`` (the run's :meth:`check_params`) unless the run's check is
        kept; an exception it raises goes out, and the run is not kept."""
        key = run_key(spec)
        if key is None or key not in self.kept_:
            check()
            self.made_ += 1
        if key is not None:
            self.passed_.add(key)

    def save(self) -> None:
        """Keep the checks passed, and only those: the file holds the config's runs'.
        A cache: where it cannot be written, a warning names it and the run goes on."""
        if self.passed_ == self.kept_:
            return
        tmp = None
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            # written whole, then renamed: two runs planned at once never read half a file
            fd, tmp = tempfile.mkstemp(dir=self.path.parent, prefix=self.path.name,
                                       suffix=".tmp")
            with os.fdopen(fd, "w") as f:
                json.dump(sorted(self.passed_), f)
            os.chmod(tmp, 0o644)
            os.replace(tmp, self.path)
        except OSError as e:
            logging.getLogger(__name__).warning(
                "the config's checks passed but could not be kept in %s: %s", self.path, e)
            if tmp is not None:
                Path(tmp).unlink(missing_ok=True)
