"""The workflow through Snakemake's cluster executors (profiles/)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

# Snakemake or pip in a subprocess, minutes in all: `pytest -m "not workflow"` skips them
pytestmark = pytest.mark.workflow

REPO = Path(__file__).resolve().parent.parent


def snakemake(workdir: Path, alfa_dir: Path, target: str, *args: str
              ) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "snakemake", target, *args, "--snakefile",
           str(REPO / "Snakefile"), "--directory", str(workdir), "--configfile",
           str(REPO / "config/config.yaml")]
    return subprocess.run(cmd, env={**os.environ, "ALFA_DIR": str(alfa_dir)},
                          capture_output=True, text=True)


def test_the_slurm_profile_is_accepted_by_a_dry_run(corpus, tmp_path):
    pytest.importorskip("snakemake_executor_plugin_slurm")
    done = snakemake(tmp_path, corpus.parent, "all", "-n", "--profile",
                     str(REPO / "profiles/slurm"))
    assert done.returncode == 0, done.stdout + done.stderr
    assert "detect" in done.stdout and "rerun_logs" in done.stdout


def test_jobs_run_through_the_generic_cluster_executor(corpus, tmp_path):
    """submit.sh stands in for sbatch: a job is submitted, runs apart, and is seen done."""
    pytest.importorskip("snakemake_executor_plugin_cluster_generic")
    submit = REPO / "profiles/local-cluster/submit.sh"
    done = snakemake(tmp_path, corpus.parent, "results/flights.csv", "--profile",
                     str(REPO / "profiles/local-cluster"), "--cluster-generic-submit-cmd",
                     str(submit))
    assert done.returncode == 0, done.stdout + done.stderr
    assert (tmp_path / "results/flights.csv").exists()
    assert (tmp_path / "results/logs/cluster/snakejob.manifest.0.sh.log").exists()
