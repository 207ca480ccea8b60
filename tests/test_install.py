"""A plain, non-editable install works from any folder: every module of the package
imports, each ``alfa-bench`` command runs on a real file, and a run is scored with the
config, its schema and the scoring defaults the package ships; nothing is looked for
in the working folder. One install serves every test here: into a venv of its own,
without build isolation, its dependencies those of the test environment (named in a
``.pth`` file, whose own ``.pth`` files, the editable install's among them, are not
read), so that nothing is downloaded and nothing of the checkout is found."""

import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from workflow_runs import REPO

SCRIPT = textwrap.dedent("""
    import sys
    from pathlib import Path
    import alfa_bench as ab

    assert Path(ab.__file__).is_relative_to(sys.argv[1]), ab.__file__
    assert ab.load_config()["scoring"]["deadline_s"] > 0
    corpus = ab.load_corpus()
    assert corpus.cache.is_relative_to(sys.argv[2]), corpus.cache
    result = ab.evaluate("residual_bank", corpus)
    assert result.records and set(result.summary["subset"]) >= {"no_emr", "all"}
    other = ab.evaluate("glrt_rls", corpus)
    print(len(ab.compare(result, other)), ab.__version__)
""")

PURELIB = "import sysconfig; print(sysconfig.get_paths()['purelib'])"
# each module named, imported from where it was installed
IMPORT_ALL = textwrap.dedent("""
    import importlib
    import sys
    from pathlib import Path

    for name in sys.argv[2:]:
        module = importlib.import_module(name)
        assert Path(module.__file__).is_relative_to(sys.argv[1]), module.__file__
""")
#: the package's folders in the checkout, by the name each installs under
FOLDERS = {"alfa_bench": "alfa_bench", "config": "alfa_bench.config",
           "data": "alfa_bench.data", "methods": "alfa_bench.methods",
           "analysis": "alfa_bench.analysis", "outputs": "alfa_bench.outputs",
           "workflow": "alfa_bench.workflow"}


def _tracked():
    files = subprocess.run(["git", "ls-files", "-z"], cwd=REPO, capture_output=True,
                           check=True).stdout.decode().split("\0")
    return [name for name in files if name]


@pytest.fixture(scope="module")
def installed(corpus, tmp_path_factory):
    """The package installed, not editable, from a copy of the tracked files; the
    environment that runs it from an empty folder elsewhere, on the synthetic corpus."""
    tmp_path = tmp_path_factory.mktemp("install")
    source = tmp_path / "src"
    for name in _tracked():
        if (REPO / name).is_file():
            (source / name).parent.mkdir(parents=True, exist_ok=True)
            (source / name).write_bytes((REPO / name).read_bytes())
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    python = venv / "bin" / "python"
    site = Path(subprocess.run([python, "-c", PURELIB], capture_output=True, text=True,
                               check=True).stdout.strip())
    (site / "dependencies.pth").write_text(
        subprocess.run([sys.executable, "-c", PURELIB], capture_output=True, text=True,
                       check=True).stdout)
    done = subprocess.run([python, "-m", "pip", "install", "-q", "--no-deps",
                           "--no-build-isolation", str(source)], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    elsewhere, cache = tmp_path / "elsewhere", tmp_path / "cache"
    elsewhere.mkdir()
    env = {**os.environ, "ALFA_DIR": str(corpus.parent), "XDG_CACHE_HOME": str(cache)}
    env.pop("PYTHONPATH", None)
    return venv, site, elsewhere, cache, env


def _run(args, installed):
    *_, elsewhere, _, env = installed
    return subprocess.run(args, capture_output=True, text=True, cwd=elsewhere, env=env)


@pytest.mark.workflow
def test_a_plain_install_scores_a_run_from_another_folder(installed):
    venv, site, elsewhere, cache, _ = installed
    done = _run([venv / "bin" / "python", "-c", SCRIPT, str(site), str(cache)], installed)
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.split()[-1] == "0.1.0"
    assert not any(elsewhere.iterdir()), list(elsewhere.iterdir())


@pytest.mark.workflow
def test_a_plain_install_holds_every_module(installed):
    modules = []
    for name in _tracked():
        folder, _, rest = name.partition("/")
        if folder in FOLDERS and name.endswith(".py"):
            parts = [FOLDERS[folder], *rest.removesuffix(".py").split("/")]
            modules.append(".".join(parts).removesuffix(".__init__"))
    assert "alfa_bench.live.monitor" in modules
    venv, site = installed[:2]
    done = _run([venv / "bin" / "python", "-c", IMPORT_ALL, str(site), *modules], installed)
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.workflow
def test_each_command_of_a_plain_install_runs_on_a_real_file(installed, corpus, tmp_path):
    command = [installed[0] / "bin" / "alfa-bench"]
    done = _run([*command, "--help"], installed)
    assert done.returncode == 0, done.stderr
    listed = set(re.search(r"\{([\w,-]+)\}", done.stdout).group(1).split(","))
    flight = sorted(p.name for p in corpus.iterdir() if p.is_dir())[0]
    model, log = tmp_path / "coincidence.abm", tmp_path / "flight.tlog"
    runs = {"fit": ["coincidence", "-o", str(model)],
            "replay": [flight, "-o", str(log)],
            "monitor": [str(model), str(log)]}
    assert listed == set(runs), f"a command with no run here: {listed - set(runs)}"
    for name, args in runs.items():                # in this order: each reads the last's
        done = _run([*command, name, *args], installed)
        assert done.returncode == 0, (name, done.stdout + done.stderr)
    assert "grid steps" in done.stdout, done.stdout
