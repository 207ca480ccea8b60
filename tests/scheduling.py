"""How pytest-xdist shares the suite between its workers (`-n 2`, pyproject.toml).

The session's workflow runs (conftest.py's ``runs``, ``overlay``, ``slurm_run``) cost
minutes each, and a worker that needs one makes its own: every test that takes one of
them, with the tests sharing a fixture of its file, goes to one worker in one unit, so
they are made once and first; the rest go file by file (a module's fixtures stay on
one worker) to whichever worker is free. Two tests there also change a module of the
repo for a moment (workflow_runs.dry_run_with_changed) and compare against ``runs``:
one worker keeps them in order. xdist's own ``loadgroup`` would group by mark, but
xdist 3.8 renames the items for it through an attribute pytest 9 no longer reads; the
controller sees test ids only, so the tests are found here, in each file's source, by
the parameters of its functions.
"""

import ast
from functools import cache
from pathlib import Path

from xdist.scheduler import LoadScopeScheduling

#: the session fixtures one worker makes
SHARED = frozenset({"runs", "overlay", "slurm_run"})
#: the work unit of the tests that take one
GROUP = "the session's workflow runs"


@cache
def grouped(path: Path) -> frozenset[str]:
    """The test functions of a file that go to the group: those taking a shared
    fixture, directly or through the file's own fixtures, and those sharing one of the
    file's fixtures with them."""
    tree = ast.parse(path.read_text(), str(path))
    params = {node.name: {a.arg for a in node.args.args + node.args.kwonlyargs}
              for node in ast.walk(tree)
              if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)}
    # a union-find over the file's functions and the shared fixtures: a function is one
    # with each of its parameters that is a fixture of the file or a shared one
    parent: dict[str, str] = {}

    def root(name: str) -> str:
        while parent.get(name, name) != name:
            name = parent[name]
        return name

    for name, args in params.items():
        for arg in args & (set(params) | SHARED):
            parent[root(arg)] = root(name)
    shared = {root(name) for name in SHARED}
    return frozenset(name for name in params
                     if name.startswith("test") and root(name) in shared)


class SharedRunsScheduling(LoadScopeScheduling):
    """Load by file, but the tests of :func:`grouped` in one unit, handed out first
    (module docstring); then the files with the most tests first."""

    def __init__(self, config, log=None):
        super().__init__(config, log)
        self.rootpath = Path(config.rootpath)

    def _split_scope(self, nodeid: str) -> str:
        file, _, rest = nodeid.partition("::")
        path = self.rootpath / file
        test = rest.rsplit("::", 1)[-1].split("[", 1)[0]
        return GROUP if path.suffix == ".py" and test in grouped(path) else file

    def _assign_work_unit(self, node) -> None:
        if GROUP in self.workqueue:
            self.workqueue.move_to_end(GROUP, last=False)
        super()._assign_work_unit(node)
