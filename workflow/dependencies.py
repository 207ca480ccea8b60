"""Which source files a detector's jobs depend on: a scan of the package's imports.

The workflow gives each detect job the source files of the modules its detector runs
on (:func:`module_sources`), so that a changed module re-runs exactly the jobs of the
detectors that use it, and no other.
"""

from __future__ import annotations

import ast
import importlib
from functools import cache
from pathlib import Path

__all__ = ["module_sources"]


def module_sources(module: str) -> list[str]:
    """The source files of ``module`` and of every module it imports from ``alfa_bench``
    or from its own top-level package (a plugin's), transitively: the code a job that
    runs a detector of ``module`` depends on. A workflow rule takes them as inputs, so
    that a changed module re-runs exactly the jobs of the detectors that use it. (``from
    . import x`` names the submodule ``x`` only, not its package: a detector added to the
    package's registry is no change to the others.) The modules are read, not imported:
    every cluster job parses the workflow again, and the detector modules import numba
    (0.4 s)."""
    roots = tuple(dict.fromkeys(("alfa_bench", module.split(".")[0])))
    found: dict[str, str] = {}
    todo = [module]
    while todo:
        name = todo.pop()
        if name not in found:
            found[name], imports = _imports(name, roots)
            todo += imports
    return sorted(found.values())


@cache
def _imports(name: str, roots: tuple[str, ...]) -> tuple[str, list[str]]:
    """The source file of module ``name`` and the modules under ``roots`` it imports.
    Cached: the workflow asks once per method, and most share their modules."""
    origin, is_package = _locate(name)
    package = name if is_package else name.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(Path(origin).read_text())):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.startswith(roots)]
        elif isinstance(node, ast.ImportFrom):
            base = ("." * node.level + (node.module or "")) if node.level else node.module
            base = importlib.util.resolve_name(base, package)
            if not base.startswith(roots):
                continue
            names = [] if node.module is None else [base]
            found += [m for m in (*names, *(f"{base}.{a.name}" for a in node.names))
                      if m == base or _locate(m) is not None]
    return origin, found


@cache
def _locate(name: str) -> tuple[str, bool] | None:
    """The source file of module ``name`` and whether it is a package; None where
    ``name`` is no module (``module.Class``). Each parent is looked up first and must
    be a package: looking a name up inside a module would import that module (and
    numba with a detector's). A package's ``__init__`` is imported to look inside it."""
    try:
        if "." in name:
            parent = _locate(name.rpartition(".")[0])
            if parent is None or not parent[1]:
                return None
        spec = importlib.util.find_spec(name)
    except ModuleNotFoundError:
        return None
    if spec is None or spec.origin is None:
        return None
    return spec.origin, spec.submodule_search_locations is not None
