"""Which source files a job depends on: a scan of the package's imports.

The workflow gives each detect job the source files of the modules its detector runs
on (:func:`module_sources`), and each script's job those of the modules its script
imports (:func:`script_sources`), so that a changed module re-runs exactly the jobs that
use it (and those after them), and no other.
"""

from __future__ import annotations

import ast
import importlib
import re
from functools import cache
from pathlib import Path

__all__ = ["module_sources", "script_sources"]


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
    return _follow([module], roots)


@cache
def script_sources(path: str | Path) -> list[str]:
    """The source files of the modules of ``alfa_bench`` that the script at ``path``
    (a workflow rule's ``script:``, not a module) imports, and of every module they
    import, transitively: a rule's input, so that a changed module re-runs its job.
    (Snakemake follows the script's own text.) Read, not imported, as
    :func:`module_sources`."""
    return _follow(_imported(Path(path), "", ("alfa_bench",)), ("alfa_bench",))


def _follow(modules: list[str], roots: tuple[str, ...]) -> list[str]:
    """The source files of ``modules`` and of every module under ``roots`` they import."""
    found: dict[str, str] = {}
    todo = list(modules)
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
    return origin, _imported(Path(origin), name if is_package else name.rpartition(".")[0],
                             roots)


def _imported(path: Path, package: str, roots: tuple[str, ...]) -> list[str]:
    """The modules under ``roots`` that the source at ``path`` imports, anywhere in it (a
    function's import too); ``package`` resolves its relative imports."""
    found = []
    for node in _import_statements(path.read_text()):
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
    return found


#: a line that starts an import statement, and a parenthesised one's other lines
_IMPORT = re.compile(r"^[ \t]*(?:from[ \t]+[\w.]+[ \t]+import[ \t]*(?:\([^)]*\).*|.*)"
                     r"|import[ \t]+.*)$", re.MULTILINE)


def _import_statements(text: str) -> list[ast.stmt]:
    """The import statements of the source ``text``, anywhere in it (a function's too),
    parsed one by one: parsing the whole module (the workflow does it for every module
    of every job, on each parse) costs over ten times as much. A line of a string that
    reads as an import is one too: a dependency more, never one less."""
    found = []
    for match in _IMPORT.finditer(text):
        try:
            found += ast.parse(match.group().strip()).body
        except SyntaxError:
            continue                 # prose in a docstring
    return found


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
