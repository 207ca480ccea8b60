"""How pytest-xdist shares the suite between its workers (`-n 2`, pyproject.toml).

The session's workflow runs cost minutes each. Two units go first, one to each worker:
the tests of the reference runs (conftest.py's ``runs``; ``overlay``, the config every
run shares), and the tests of the other runs (conftest.py's ``slurm_run``, and a file's
fixture that takes ``overlay``, which makes a run of its own), each unit with the tests
sharing a fixture of its file with them; so both workers make runs from the start,
each run once. A test of the second unit that compares with ``runs`` reads the
reference runs the first worker made (conftest.py makes them once per session,
whichever worker asks first, and the other waits for them; it orders the SLURM run's
tests last). The rest go file by file (a module's fixtures stay on one worker) to
whichever worker is free, first those of a file that marks a test ``workflow`` or
``slow`` (a subprocess, a browser: seconds to a minute each; :func:`marked`), then
the others, each kind with the most tests first: a heavy file handed out last kept one
worker busy for a minute and a half after the other had ended. xdist's own
``loadgroup`` would group by mark, but xdist 3.8
renames the items for it through an attribute pytest 9 no longer reads; the controller
sees test ids only, so the tests are found here, in each file's source, by the
parameters of its functions. The contract's checks go by detector (:data:`BY_DETECTOR`).
"""

import ast
from collections import OrderedDict
from functools import cache
from pathlib import Path

from xdist.scheduler import LoadScopeScheduling

#: the reference runs' fixtures, and the other session run's
REFERENCE, OTHER = frozenset({"runs", "overlay"}), frozenset({"slurm_run"})
#: the two work units
GROUPS = ("the reference workflow runs", "the other workflow runs")
#: tests of methods.contract.parametrize_with_checks (ids ``<detector>-<check>``), a unit
#: per detector (its checks share its fit, kept per process): as one file they were
#: one unit of seven minutes, which left the other worker idle at the end
BY_DETECTOR = frozenset({"test_contract"})


@cache
def grouped(path: Path) -> dict[str, str]:
    """The test functions of a file that go to a unit of :data:`GROUPS`, with their
    unit: the tests joined by the file's own fixtures (a union-find) go together; to the
    second unit when one of them takes :data:`OTHER` or is a fixture making a run of its
    own (it takes ``overlay``), else to the first when one takes :data:`REFERENCE`."""
    tree = ast.parse(path.read_text(), str(path))
    params = {node.name: {a.arg for a in node.args.args + node.args.kwonlyargs}
              for node in ast.walk(tree)
              if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)}
    parent: dict[str, str] = {}

    def root(name: str) -> str:
        while parent.get(name, name) != name:
            name = parent[name]
        return name

    for name, args in params.items():
        for arg in args & set(params):
            parent[root(arg)] = root(name)
    other = {root(n) for n, args in params.items()
             if args & OTHER or ("overlay" in args and not n.startswith("test"))}
    reference = {root(n) for n, args in params.items() if args & REFERENCE} - other
    return {n: GROUPS[1] if root(n) in other else GROUPS[0] for n in params
            if n.startswith("test") and root(n) in other | reference}


#: the marks of tests that take seconds or more each (pyproject.toml's markers)
HEAVY = frozenset({"workflow", "slow"})


@cache
def marked(path: Path) -> bool:
    """Whether the file marks any test :data:`HEAVY`: its ``pytestmark``, or a test
    function's ``@pytest.mark.<name>``."""
    tree = ast.parse(path.read_text(), str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and node.attr in HEAVY and isinstance(
                node.value, ast.Attribute) and node.value.attr == "mark":
            return True
    return False


class SharedRunsScheduling(LoadScopeScheduling):
    """Load by file, but the tests of :func:`grouped` in their two units, handed out
    first (module docstring); then the units of :func:`marked` files, then the rest,
    each with the most tests first."""

    def __init__(self, config, log=None):
        super().__init__(config, log)
        self.rootpath = Path(config.rootpath)
        self.ordered = False

    def _split_scope(self, nodeid: str) -> str:
        file, _, rest = nodeid.partition("::")
        path = self.rootpath / file
        test, _, case = rest.rsplit("::", 1)[-1].partition("[")
        if test in BY_DETECTOR:
            return f"{file}::{case.rsplit('-', 1)[0]}"
        return grouped(path).get(test, file) if path.suffix == ".py" else file

    def _rank(self, scope: str) -> int:
        if scope in GROUPS:
            return GROUPS.index(scope)
        path = self.rootpath / scope.partition("::")[0]
        return len(GROUPS) + (0 if path.suffix == ".py" and marked(path) else 1)

    def _assign_work_unit(self, node) -> None:
        if not self.ordered:    # xdist queued them by their number of tests: kept within a rank
            self.workqueue = OrderedDict(
                (scope, self.workqueue[scope]) for scope in sorted(self.workqueue,
                                                                   key=self._rank))
            self.ordered = True
        super()._assign_work_unit(node)
