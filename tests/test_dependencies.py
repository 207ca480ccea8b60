"""Which source files a run's jobs depend on (workflow/dependencies.py): a detector's
modules read, not imported, and a plugin's own modules followed as the project's are."""

import subprocess
import sys
import textwrap

from alfa_bench.methods import detector_module
from alfa_bench.workflow.dependencies import module_sources


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
                                       "alfa_bench.methods.extremes"]), done.stdout


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
