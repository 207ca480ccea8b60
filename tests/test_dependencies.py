"""Which source files a run's jobs depend on (workflow/dependencies.py): a detector's
modules read, not imported, and a plugin's own modules followed as the project's are;
a script's modules too, so that a changed module re-runs the aggregates that use it."""

import re
import shutil
import subprocess
import sys
import textwrap

import pytest
from workflow_runs import REPO, dry_run_with_changed

from alfa_bench.methods import detector_module
from alfa_bench.workflow.dependencies import module_sources, script_sources


def test_a_builtin_detector_depends_on_its_modules_and_imports_none():
    sources = module_sources(detector_module("rls_arx_zscore"))
    names = {s.rsplit("/", 2)[-2] + "/" + s.rsplit("/", 1)[-1] for s in sources}
    assert {"methods/rls_arx_zscore.py", "methods/base.py", "methods/kernels.py",
            "data/signals.py"} <= names
    assert "methods/residual_bank.py" not in names
    # read, not imported, in a process of its own (a cluster job's parse): no detector
    # module, no numba
    code = ("import sys; from alfa_bench.methods import detector_module, BUILTIN_ENTRIES; "
            "from alfa_bench.workflow.dependencies import module_sources; "
            "[module_sources(detector_module(n)) for n in BUILTIN_ENTRIES]; "
            "print(sorted(m for m in sys.modules if m == 'numba' or "
            "m.startswith('alfa_bench.methods.')))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True)
    assert done.stdout.strip() == str(["alfa_bench.methods.base",
                                       "alfa_bench.methods.extremes",
                                       "alfa_bench.methods.unmoved"]), done.stdout


def test_a_plugin_package_is_followed_into_its_own_modules(tmp_path, monkeypatch):
    pkg = tmp_path / "alfa_foo"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("from .detector import Foo\n")
    (pkg / "detector.py").write_text(textwrap.dedent("""
        from alfa_bench.methods.base import Detector
        from . import helpers


        class Foo(Detector):
            pass
        """))
    (pkg / "helpers.py").write_text("X = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    sources = {p.rsplit("/", 1)[-1] for p in module_sources("alfa_foo")}
    assert {"__init__.py", "detector.py", "helpers.py", "base.py"} <= sources


def test_a_script_depends_on_the_modules_it_imports_and_theirs():
    names = {"/".join(s.rsplit("/", 2)[-2:]) for s in script_sources(REPO / "scripts/tables.py")}
    assert {"outputs/tables.py", "analysis/scoring.py", "data/manifest.py"} <= names
    manifest = {"/".join(s.rsplit("/", 2)[-2:])
                for s in script_sources(REPO / "scripts/manifest.py")}
    assert "outputs/tables.py" not in manifest and "data/manifest.py" in manifest


#: the jobs a changed module plans in a run that is up to date: those whose scripts
#: import it, and those after them; a module no rule runs plans none
AFTER_A_CHANGE = {
    "outputs/tables.py": {"tables", "index_page", "paper_sources", "features_learners",
                          "provenance", "all", *(["paper_pdf"] if shutil.which("latexmk")
                                                 else [])},
    "alfa_bench/live/monitor.py": set(),
}


@pytest.mark.workflow
@pytest.mark.parametrize("module", AFTER_A_CHANGE)
def test_a_changed_module_reruns_the_jobs_that_import_it_and_those_after(runs, overlay,
                                                                         module):
    """A dry run over the reference run, with ``module``'s text changed by one comment
    line (Snakemake compares small inputs by content) and restored byte for byte."""
    done = dry_run_with_changed(REPO / module, runs[1], overlay, "test_dependencies")
    assert done.returncode == 0, done.stdout + done.stderr
    planned = set(re.findall(r"^(?:local)?rule (\w+):$", done.stdout, re.MULTILINE))
    assert planned == AFTER_A_CHANGE[module], done.stdout
    assert planned or "Nothing to be done" in done.stdout, done.stdout
