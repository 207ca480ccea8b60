"""Detectors from other packages: the entry-point registry, and the worked example
(`examples/alfa-cusum`) installed, checked by the contract test and run by the workflow
without touching `methods/`."""

import os
import shutil
import subprocess
import sys
from importlib.metadata import EntryPoint
from pathlib import Path

import pytest
import yaml

import alfa_bench.methods as methods

REPO = Path(__file__).resolve().parent.parent
EXAMPLE = REPO / "examples/alfa-cusum"


def test_a_plugin_may_not_shadow_a_builtin_or_be_something_else(monkeypatch):
    def fake(*entries):
        monkeypatch.setattr(methods, "entry_points", lambda group: [
            EntryPoint(name, value, group) for name, value in entries])

    fake(("glrt_residuals", "alfa_bench.methods.end_of_flight:EndOfFlight"))
    with pytest.raises(ImportError, match="shadow the built-in detector 'glrt_residuals'"):
        methods.plugins()
    fake(("thing", "alfa_bench.methods:make_detector"))
    with pytest.raises(TypeError, match="thing = 'alfa_bench.methods:make_detector'"):
        methods.plugins()
    fake(("mine", "alfa_bench.methods.end_of_flight:EndOfFlight"))
    assert methods.plugins() == {"mine": methods.BUILTIN["end_of_flight"]}


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """The example package installed (without dependencies: alfa-bench is here), from a
    copy so that the build leaves nothing in the checkout, into a folder of its own,
    which PYTHONPATH then adds: the venv itself stays as it is."""
    site = tmp_path_factory.mktemp("site")
    source = shutil.copytree(EXAMPLE, tmp_path_factory.mktemp("src") / EXAMPLE.name)
    done = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps",
                           "--no-build-isolation", "--target", str(site), str(source)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    return {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(site), *filter(None, [os.environ.get("PYTHONPATH")])])}


@pytest.mark.workflow
def test_the_installed_plugin_is_registered_and_passes_the_contract(installed):
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "-n", "0", str(REPO / "tests/test_contract.py"), "-k",
                           "registry:cusum"],
                          capture_output=True, text=True, env=installed, cwd=REPO)
    assert done.returncode == 0, done.stdout + done.stderr
    passed = int(done.stdout.strip().splitlines()[-1].split()[0])
    assert passed >= 10, done.stdout


@pytest.mark.workflow
def test_the_plugin_checks_itself_with_parametrize_with_checks(installed, tmp_path):
    """The example's own test file, run from a copy as its author would: every check of
    alfa_bench.methods.contract on two of its configurations."""
    own = shutil.copy(EXAMPLE / "test_alfa_cusum.py", tmp_path)
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           str(own)], capture_output=True, text=True, env=installed,
                          cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    from alfa_bench.methods.contract import CHECKS
    assert f"{2 * len(CHECKS)} passed" in done.stdout, done.stdout


@pytest.mark.workflow
def test_a_config_run_of_the_plugin_lands_in_the_comparison(installed, runs, overlay,
                                                            tmp_path):
    """On a copy of the reference run, with the same config plus one run of the plugin:
    the plugin's detect job runs and its row lands in the comparison, while the other
    methods' detections are kept, not redone."""
    work = tmp_path / "run"
    shutil.copytree(runs[0], work, symlinks=True)
    kept = (work / "results/detections/rls_arx_zscore").stat().st_mtime_ns
    extra = tmp_path / "plugin.yaml"
    extra.write_text(yaml.safe_dump({"methods": {"cusum_roll": {"detector": "cusum"}}}))
    env = {k: v for k, v in installed.items() if k != "ALFA_DIR"}   # the run's download
    done = subprocess.run([sys.executable, "-m", "snakemake", "results/tables/comparison.md",
                           "--cores", "2", "--quiet", "--snakefile", str(REPO / "Snakefile"),
                           "--directory", str(work), "--configfile",
                           str(REPO / "config/config.yaml"), str(overlay), str(extra)],
                          capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    table = (work / "results/tables/comparison.md").read_text()
    assert "| cusum_roll | cusum |" in table
    assert (work / "results/detections/rls_arx_zscore").stat().st_mtime_ns == kept
