"""The workflow through Snakemake's cluster executors (profiles/), and through a real
one-node SLURM cluster (tests/slurm_cluster.py, brought up by conftest's slurm_run)."""

import os
import re
import subprocess
import sys
from collections import Counter
from pathlib import Path

import pytest
from slurm_cluster import ACCOUNT, PARTITION, slurm_unavailable
from unavailable import require_module, unavailable
from workflow_runs import assert_same_results

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
    require_module("snakemake_executor_plugin_slurm")
    done = snakemake(tmp_path, corpus.parent, "all", "-n", "--profile",
                     str(REPO / "profiles/slurm"))
    assert done.returncode == 0, done.stdout + done.stderr
    assert "detect" in done.stdout and "run_parts" in done.stdout


def test_jobs_run_through_the_generic_cluster_executor(corpus, tmp_path):
    """submit.sh stands in for sbatch: a job is submitted, runs apart, and is seen done."""
    require_module("snakemake_executor_plugin_cluster_generic")
    submit = REPO / "profiles/local-cluster/submit.sh"
    done = snakemake(tmp_path, corpus.parent, "results/flights.csv", "--profile",
                     str(REPO / "profiles/local-cluster"), "--cluster-generic-submit-cmd",
                     str(submit))
    assert done.returncode == 0, done.stdout + done.stderr
    assert (tmp_path / "results/flights.csv").exists()
    assert (tmp_path / "results/logs/cluster/snakejob.manifest.0.sh.log").exists()


@pytest.fixture(scope="module")
def through_slurm(slurm_run):
    if slurm_run is None:
        unavailable(slurm_unavailable())
    done = slurm_run.done
    assert done.returncode == 0, (done.stdout + done.stderr)[-6000:]
    return slurm_run


def _minutes(limit: str) -> int:
    """sacct's ``[days-]hours:minutes:seconds`` in minutes."""
    days, _, clock = limit.rpartition("-")
    h, m, _ = (int(x) for x in clock.split(":"))
    return (int(days or 0) * 24 + h) * 60 + m


def _planned(stdout: str) -> Counter:
    """The jobs of the run's plan, by rule, from Snakemake's job stats."""
    table = stdout.split("Job stats:", 1)[1].split("total", 1)[0]
    return Counter({rule: int(n) for rule, n in re.findall(r"^(\w+)\s+(\d+)$", table, re.M)})


def test_every_job_goes_through_slurm_with_its_own_log(through_slurm):
    """Each job of the run's targets is submitted with sbatch, is in SLURM's accounting
    with the profile's account and partition and its rule and wildcards as comment, and
    leaves a SLURM log named for its job id."""
    run = through_slurm
    log = run.done.stderr                    # Snakemake logs there
    submitted = re.findall(r"Job (\d+) has been submitted with SLURM jobid (\d+)", log)
    planned = _planned(log)
    ids = [r["JobID"] for r in run.accounting]
    assert sorted(ids, key=int) == sorted((slurm for _, slurm in submitted), key=int)
    # one SLURM job more than planned jobs: the detect job killed once ran again
    assert len(ids) == len({job for job, _ in submitted}) + 1
    assert len({job for job, _ in submitted}) == planned.total() >= 8
    assert planned["detect"] == 3 and planned["detect_reference"] == 1
    assert {r["Account"] for r in run.accounting} == {ACCOUNT}
    assert {r["Partition"] for r in run.accounting} == {PARTITION}
    done = Counter(r["Comment"].split("_wildcards_")[0].removeprefix("rule_")
                   for r in run.accounting if r["State"] == "COMPLETED")
    assert done == planned
    logs = {p.stem for p in (run.workdir / ".snakemake/slurm_logs").rglob("*.log")}
    assert logs == set(ids)


def test_a_job_that_fails_once_is_retried_and_completes(through_slurm):
    """The profile's `retries: 1`: the detect job killed while it ran (SLURM: FAILED)
    is submitted again, with twice its memory and time, and that attempt completes."""
    run = through_slurm
    assert run.killed, "no detect job was seen running"
    rows = [r for r in run.accounting if r["Comment"] == run.killed["Comment"]]
    assert [r["State"] for r in rows] == ["FAILED", "COMPLETED"]
    first, again = rows
    assert int(again["ReqMem"].rstrip("M")) == 2 * int(first["ReqMem"].rstrip("M"))
    assert _minutes(again["Timelimit"]) == 2 * _minutes(first["Timelimit"])
    assert "Trying to restart job" in run.done.stderr


def test_results_through_slurm_are_the_local_runs(through_slurm, runs):
    """Each result file, made by jobs on the cluster, is the local run's byte for byte:
    the shared results folder and the methods' numba cache work from inside jobs."""
    assert assert_same_results(runs[0], through_slurm.workdir, part=True) > 50


def test_the_cluster_is_stopped_after_the_run(through_slurm):
    """No daemon nor job step outlives the cluster."""
    assert through_slurm.left_running == []
