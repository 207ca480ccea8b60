"""The rooms lean one way: the evaluation core (analysis/) imports neither what a run
writes (outputs/), nor the workflow's helpers, nor the Python route above both."""

import ast
import importlib.util
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
ABOVE = ("alfa_bench.outputs", "alfa_bench.workflow", "alfa_bench.evaluation")


def _imports(path: Path, package: str) -> list[str]:
    """The modules ``path``, a module of ``package``, imports: a relative import
    resolved (``from ..outputs import x`` in ``alfa_bench.analysis`` is
    ``alfa_bench.outputs``), and ``from . import x`` as both ``.`` and ``.x``."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = (importlib.util.resolve_name("." * node.level + (node.module or ""),
                                                package) if node.level else node.module)
            found += [base, *(f"{base}.{a.name}" for a in node.names)]
        elif isinstance(node, ast.Import):
            found += [a.name for a in node.names]
    return found


def _room(room: str) -> list[Path]:
    return sorted((REPO / room).glob("*.py"))


def test_analysis_imports_nothing_above_it():
    modules = _room("analysis")
    assert len(modules) > 10
    for path in modules:
        bad = [m for m in _imports(path, "alfa_bench.analysis") if m.startswith(ABOVE)]
        assert not bad, (path.name, bad)


def test_methods_and_data_import_no_room_above_them():
    for room in ("methods", "data"):
        for path in _room(room):
            bad = [m for m in _imports(path, f"alfa_bench.{room}")
                   if m.startswith((*ABOVE, "alfa_bench.analysis"))]
            assert not bad, (room, path.name, bad)


def test_a_relative_import_of_a_room_above_is_seen(tmp_path):
    path = tmp_path / "sneaky.py"
    for line, seen in [("from ..outputs import records", "alfa_bench.outputs"),
                       ("from .. import workflow", "alfa_bench.workflow"),
                       ("from ..evaluation.compare import compare", "alfa_bench.evaluation"),
                       ("from alfa_bench.outputs import records", "alfa_bench.outputs")]:
        path.write_text(line + "\n")
        assert any(m.startswith(seen) for m in _imports(path, "alfa_bench.analysis")), line
    path.write_text("from .scoring import score\nfrom ..data import SIGNALS\n")
    assert not [m for m in _imports(path, "alfa_bench.analysis") if m.startswith(ABOVE)]


def test_the_workflows_modules_import_in_no_circle():
    """The fork server takes what it runs as an argument (``start``'s ``jobs``): it
    imports no module of the workflow that imports it, as it once did the detect job's."""
    room = {p.stem: p for p in _room("workflow") if p.stem != "__init__"}
    graph = {name: {m.split(".")[2] for m in _imports(path, "alfa_bench.workflow")
                    if m.startswith("alfa_bench.workflow.")} & set(room)
             for name, path in room.items()}
    assert "forkserver" in graph["detect_job"]

    def circle(name, path):
        if name in path:
            return path[path.index(name):] + [name]
        return next((c for n in sorted(graph[name]) if (c := circle(n, [*path, name]))), None)

    assert not [c for name in graph if (c := circle(name, []))]
