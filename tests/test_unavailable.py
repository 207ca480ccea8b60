"""A test that needs what the machine lacks skips locally and fails in CI."""

import pytest
from unavailable import require_module, unavailable


def test_a_missing_need_skips_locally_and_fails_in_ci(monkeypatch):
    monkeypatch.delenv("CI", raising=False)
    with pytest.raises(pytest.skip.Exception, match="no Chromium"):
        unavailable("no Chromium")
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match="CI must run this test: no Chromium"):
        unavailable("no Chromium")
    with pytest.raises(pytest.fail.Exception, match="no_such_module_here"):
        require_module("no_such_module_here")
    assert require_module("json").dumps([]) == "[]"
