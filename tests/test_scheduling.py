"""The order the suite's units go to the workers in (tests/scheduling.py)."""

from collections import OrderedDict
from pathlib import Path
from types import SimpleNamespace

from scheduling import GROUPS, SharedRunsScheduling, marked
from xdist.scheduler import LoadScopeScheduling


def _file(folder: Path, name: str, text: str) -> str:
    (folder / name).write_text(text)
    return name


def test_a_file_is_heavy_when_it_or_one_of_its_tests_is_marked_workflow_or_slow(tmp_path):
    module = _file(tmp_path, "a.py", "import pytest\npytestmark = pytest.mark.workflow\n")
    one = _file(tmp_path, "b.py", "import pytest\n\n@pytest.mark.slow\ndef test_x():\n"
                "    pass\n\ndef test_y():\n    pass\n")
    other = _file(tmp_path, "c.py", "import pytest\n\n@pytest.mark.parametrize('a', [1])\n"
                  "def test_x(a):\n    assert 'slow' and 'workflow'\n")
    assert [marked(tmp_path / n) for n in (module, one, other)] == [True, True, False]


def test_the_runs_go_first_then_the_heavy_files_then_the_rest_each_as_xdist_queued(
        tmp_path, monkeypatch):
    """xdist queues the units by their number of tests; each rank keeps that order."""
    light = _file(tmp_path, "test_light.py", "def test_x():\n    pass\n")
    heavy = _file(tmp_path, "test_heavy.py", "import pytest\n\n@pytest.mark.slow\n"
                  "def test_x():\n    pass\n")
    heavier = _file(tmp_path, "test_heavier.py", "import pytest\n"
                    "pytestmark = pytest.mark.workflow\n")
    queued = [light, f"{light}::unit", heavy, GROUPS[1], heavier, GROUPS[0]]
    scheduler = SharedRunsScheduling.__new__(SharedRunsScheduling)
    scheduler.rootpath, scheduler.ordered = tmp_path, False
    scheduler.workqueue = OrderedDict((scope, {}) for scope in queued)
    taken = []
    # xdist's own assignment: the first unit of the queue to the node
    monkeypatch.setattr(LoadScopeScheduling, "_assign_work_unit", lambda self, node: (
        taken.append(self.workqueue.popitem(last=False)[0])))
    for _ in queued:
        scheduler._assign_work_unit(SimpleNamespace())
    assert taken == [GROUPS[0], GROUPS[1], heavy, heavier, light, f"{light}::unit"]
