"""The rooms lean one way: the evaluation core (analysis/) imports neither what a run
writes (outputs/), nor the workflow's helpers, nor the Python route above both."""

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
ABOVE = ("alfa_bench.outputs", "alfa_bench.workflow", "alfa_bench.evaluation")


def _imports(path: Path) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and not node.level:
            found.append(node.module)
        elif isinstance(node, ast.Import):
            found += [a.name for a in node.names]
    return found


def test_analysis_imports_nothing_above_it():
    modules = sorted((REPO / "analysis").glob("*.py"))
    assert len(modules) > 10
    for path in modules:
        bad = [m for m in _imports(path) if m.startswith(ABOVE)]
        assert not bad, (path.name, bad)


def test_methods_and_data_import_no_room_above_them():
    for room in ("methods", "data"):
        for path in sorted((REPO / room).glob("*.py")):
            bad = [m for m in _imports(path)
                   if m.startswith((*ABOVE, "alfa_bench.analysis"))]
            assert not bad, (room, path.name, bad)
