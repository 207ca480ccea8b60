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
    """The source files of ``module`` and of every ``alfa_bench`` module it imports,
    transitively: the code a job that runs a detector of ``module`` depends on. A
    workflow rule takes them as inputs, so that a changed module re-runs exactly the
    jobs of the detectors that use it. (``from . import x`` names the submodule ``x``
    only, not its package: a detector added to the package's registry is no change to
    the others.) The modules are read, not imported: every cluster job parses the
    workflow again, and the detector modules import numba (0.4 s)."""
    found: dict[str, str] = {}
    todo = [module]
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
    spec = importlib.util.find_spec(name)
    package = name if spec.submodule_search_locations is not None else name.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(Path(spec.origin).read_text())):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.startswith("alfa_bench")]
        elif isinstance(node, ast.ImportFrom):
            base = ("." * node.level + (node.module or "")) if node.level else node.module
            base = importlib.util.resolve_name(base, package)
            if not base.startswith("alfa_bench"):
                continue
            names = [] if node.module is None else [base]
            found += [m for m in (*names, *(f"{base}.{a.name}" for a in node.names))
                      if m == base or _is_module(m)]
    return spec.origin, found


def _is_module(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except ModuleNotFoundError:
        return False
