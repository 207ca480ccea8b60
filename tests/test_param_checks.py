"""The config's checks of each run's parameters, kept between runs (workflow/param_checks.py)."""

import json
import logging
import os
import sys

import pytest

from alfa_bench.workflow import param_checks
from alfa_bench.workflow.param_checks import KeptChecks, run_key

SPEC = {"detector": "pyod", "params": {"model": "KNN", "false_alarm": 0.1}}


class Calls:
    def __init__(self, error=None):
        self.n, self.error = 0, error

    def __call__(self):
        self.n += 1
        if self.error:
            raise self.error


def test_a_passed_check_is_not_made_again_and_a_changed_run_is(tmp_path):
    path = tmp_path / "checks.json"
    first = KeptChecks(path)
    calls = Calls()
    first.check(SPEC, calls)
    first.save()
    assert calls.n == 1 and first.made_ == 1
    again = KeptChecks(path)
    again.check(SPEC, calls)
    assert calls.n == 1 and again.made_ == 0
    changed = {**SPEC, "params": {**SPEC["params"], "false_alarm": 0.05}}
    again.check(changed, calls)
    assert calls.n == 2
    again.save()
    # only the runs of this config are kept
    assert sorted(json.loads(path.read_text())) == sorted({run_key(SPEC), run_key(changed)})


def test_a_failed_check_goes_out_and_is_never_kept(tmp_path):
    path = tmp_path / "checks.json"
    kept = KeptChecks(path)
    with pytest.raises(ValueError, match="cannot be built"):
        kept.check(SPEC, Calls(ValueError("pyod model 'KNN' cannot be built")))
    kept.save()
    calls = Calls()
    KeptChecks(path).check(SPEC, calls)
    assert calls.n == 1


@pytest.mark.parametrize("text", ["{not json", '{"a": 1}', "[1, 2]", "", "[" * 100_000,
                                  b"\xff\xfe"])
def test_an_unreadable_file_is_checked_anew_and_written_again(tmp_path, text):
    path = tmp_path / "checks.json"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    kept, calls = KeptChecks(path), Calls()
    kept.check(SPEC, calls)
    kept.save()
    assert calls.n == 1 and json.loads(path.read_text()) == [run_key(SPEC)]


@pytest.mark.parametrize("kind", ["folder", "pipe"])
def test_a_folder_or_pipe_in_its_place_is_not_read_and_the_run_goes_on(tmp_path, kind,
                                                                        caplog):
    path = tmp_path / "checks.json"
    path.mkdir() if kind == "folder" else os.mkfifo(path)
    kept, calls = KeptChecks(path), Calls()
    kept.check(SPEC, calls)
    with caplog.at_level(logging.WARNING):
        kept.save()
    assert calls.n == 1
    assert [p.name for p in tmp_path.iterdir()] == ["checks.json"]   # no temporary left
    if kind == "folder":    # not replaced: named, and the run goes on
        assert "could not be kept in" in caplog.text
    else:                   # replaced by the file
        assert json.loads(path.read_text()) == [run_key(SPEC)]


def test_parameters_json_cannot_order_are_checked_every_time(tmp_path):
    spec = {"detector": "pyod", "params": {"model": "KNN",
                                           "params": {"metric_params": {1: 2, "p": 3}}}}
    assert run_key(spec) is None
    calls = Calls()
    for _ in range(2):
        kept = KeptChecks(tmp_path / "checks.json")
        kept.check(spec, calls)
        kept.save()
    assert calls.n == 2


def test_other_code_or_library_versions_check_again(tmp_path, monkeypatch):
    path = tmp_path / "checks.json"
    kept = KeptChecks(path)
    kept.check(SPEC, Calls())
    kept.save()
    monkeypatch.setattr(param_checks, "_code_and_versions", lambda: "other code")
    calls = Calls()
    KeptChecks(path).check(SPEC, calls)
    assert calls.n == 1


def _key_moves_and_comes_back(monkeypatch, owner, name, value) -> None:
    """The code and versions part of the key differs with ``owner.name`` set to
    ``value``, and is what it was once it is undone."""
    before = param_checks._code_and_versions()
    monkeypatch.setattr(owner, name, value)
    param_checks._code_and_versions.cache_clear()
    try:
        assert param_checks._code_and_versions() != before
    finally:
        monkeypatch.undo()
        param_checks._code_and_versions.cache_clear()
    assert param_checks._code_and_versions() == before


def test_a_library_installed_or_removed_checks_again(tmp_path, monkeypatch):
    """A model may need a library alfa-bench does not install (xgboost, torch)."""
    (tmp_path / "xgboost-3.0.0.dist-info").mkdir()
    _key_moves_and_comes_back(monkeypatch, sys, "path", [*sys.path, str(tmp_path)])


def test_the_key_reads_every_detector_source_file(tmp_path, monkeypatch):
    """A module of the detectors that the registry does not import changes the key too."""
    import alfa_bench.methods

    extra = tmp_path / "methods"
    extra.mkdir()
    (extra / "new_method.py").write_text("X = 1\n")
    _key_moves_and_comes_back(monkeypatch, alfa_bench.methods, "__path__",
                              [*alfa_bench.methods.__path__, str(extra)])


def test_a_plugins_run_is_checked_every_time(tmp_path):
    """Its source is not alfa-bench's, so no key names it; nor a nested run over it."""
    path = tmp_path / "checks.json"
    for spec in ({"detector": "cusum", "params": {"h": 5.0}},
                 {"detector": "nested_selection", "params": {"detector": "cusum"}}):
        calls = Calls()
        for _ in range(2):
            kept = KeptChecks(path)
            kept.check(spec, calls)
            kept.save()
        assert calls.n == 2 and run_key(spec) is None
