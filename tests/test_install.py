"""A plain, non-editable install scores a run from any folder: the config, its schema
and the scoring defaults ship inside the package, and nothing is looked for in the
working folder."""

import os
import subprocess
import sys
import textwrap

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


@pytest.mark.workflow
def test_a_plain_install_scores_a_run_from_another_folder(corpus, tmp_path):
    files = subprocess.run(["git", "ls-files", "-z"], cwd=REPO, capture_output=True,
                           check=True).stdout.decode().split("\0")
    source = tmp_path / "src"
    for name in filter(None, files):
        if (REPO / name).is_file():
            (source / name).parent.mkdir(parents=True, exist_ok=True)
            (source / name).write_bytes((REPO / name).read_bytes())
    site = tmp_path / "site"
    done = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps",
                           "--no-build-isolation", "--target", str(site), str(source)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    elsewhere, cache = tmp_path / "elsewhere", tmp_path / "cache"
    elsewhere.mkdir()
    env = {**os.environ, "PYTHONPATH": str(site), "ALFA_DIR": str(corpus.parent),
           "XDG_CACHE_HOME": str(cache)}
    done = subprocess.run([sys.executable, "-c", SCRIPT, str(site), str(cache)],
                          capture_output=True, text=True, cwd=elsewhere, env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.split()[-1] == "0.1.0"
    assert not any(elsewhere.iterdir()), list(elsewhere.iterdir())
