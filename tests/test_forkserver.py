"""The detect jobs' fork server (workflow/forkserver.py): a job forked from it behaves
as the job run alone would, toward Snakemake: its output, its exit status, its death
with its client; and where no server answers, the job runs in its own process."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from alfa_bench.workflow import detect_job, forkserver
from alfa_bench.workflow.detect_job import CONFIG_ENV, SERVER_ENV, write_job_config

TESTS = Path(__file__).resolve().parent
_CLIENT = ("import sys; from alfa_bench.workflow.forkserver import submit; "
           "s = submit(sys.argv[1], sys.argv[2:]); sys.exit(99 if s is None else s)")


def client(path, *argv, **kw) -> subprocess.CompletedProcess:
    """A job's client, as the rule's command runs it; exit 99: no server took it."""
    return subprocess.run([sys.executable, "-c", _CLIENT, str(path), *argv],
                          capture_output=True, text=True, timeout=60, **kw)


def _wait(check, what, timeout_s=20.0):
    deadline = time.monotonic() + timeout_s
    while not check():
        assert time.monotonic() < deadline, what
        time.sleep(0.05)


def _gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    # a zombie is gone but for its parent's wait
    return Path(f"/proc/{pid}/stat").read_text().split()[2] == "Z"


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    path = tmp_path_factory.mktemp("server") / "s.sock"
    proc = subprocess.Popen([sys.executable, str(TESTS / "forkserver_jobs.py"), str(path),
                             str(os.getpid())])
    _wait(path.exists, "the server did not listen")
    yield path
    proc.terminate()
    proc.wait()


def test_a_job_writes_to_its_clients_streams_and_shares_the_servers_state(server):
    first = client(server, "echo", "a")
    second = client(server, "echo", "b")
    assert first.returncode == second.returncode == 0, first.stderr + second.stderr
    assert first.stdout.startswith("out: a prepared ") and first.stderr == "err: a\n"
    # prepared in the server before the fork: the second job sees one more
    n = int(first.stdout.split()[-1])
    assert second.stdout == f"out: b prepared {n + 1}\n"


def test_a_failed_job_fails_its_client_with_the_traceback(server):
    done = client(server, "fail")
    assert done.returncode == 1
    assert "ValueError: the job failed" in done.stderr


def test_a_job_that_failed_to_prepare_still_runs_and_fails_in_its_own_right(server):
    done = client(server, "bad-prepare")
    assert done.returncode == 1 and "ValueError: the job failed" in done.stderr


def test_a_job_the_server_does_not_take_runs_in_its_client(server, tmp_path):
    """From another folder (another workflow's job) or refused by `prepare` (its
    code changed since the server loaded it), a job is handed back untouched."""
    assert client(server, "refused").returncode == 99
    assert client(server, "echo", cwd=tmp_path).returncode == 99
    assert client(server, "echo").returncode == 0


def test_a_module_changed_after_the_preload_is_seen(monkeypatch, tmp_path):
    module = tmp_path / "m.py"
    module.write_text("")
    monkeypatch.setattr(detect_job, "_SOURCES", {str(module): module.stat().st_mtime_ns})
    assert not detect_job.code_changed()
    os.utime(module, ns=(0, module.stat().st_mtime_ns + 1))
    assert detect_job.code_changed()


def test_a_jobs_exit_status_is_its_clients(server):
    assert client(server, "exit", "3").returncode == 3
    assert client(server, "exit", "0").returncode == 0


def test_a_jobs_own_subprocesses_report_their_status(server):
    """The server lets the kernel reap its forks; a fork's own children are its to
    wait for, or `false` would seem to succeed."""
    done = client(server, "child-status")
    assert done.returncode == 0 and done.stdout == "1\n", done.stderr


def test_a_job_gone_without_a_status_fails_its_client(server):
    done = client(server, "crash")
    assert done.returncode == 1 and "ended without an exit status" in done.stderr


def test_a_killed_client_takes_its_job_with_it(server, tmp_path):
    """Snakemake stops a job by killing its command: the fork running it stops too."""
    pid_file = tmp_path / "pid"
    job = subprocess.Popen([sys.executable, "-c", _CLIENT, str(server), "sleep",
                            str(pid_file)])
    _wait(lambda: pid_file.exists() and pid_file.read_text(), "the job did not start")
    pid = int(pid_file.read_text())
    job.send_signal(signal.SIGKILL)
    job.wait()
    _wait(lambda: _gone(pid), "the job outlived its client")


def test_a_job_killed_by_the_kernel_names_the_kill_in_its_log(server, tmp_path):
    """The out-of-memory killer's SIGKILL leaves the fork no time to write a word: the
    job's log names the signal and what it likely means, and the job fails with the
    shell's status for it (128 + 9)."""
    pid_file, log = tmp_path / "pid", tmp_path / "job.log"
    files = [f"--{a}={tmp_path / a}" for a in ("manifest", "cache", "detections", "traces",
                                                "panels")]
    job = subprocess.Popen([sys.executable, "-m", "alfa_bench.workflow.detect_job",
                            "sleep-job", *files, "--config", str(tmp_path / "config.json"),
                            "--benchmark", str(pid_file), "--log", str(log)],
                           env={**os.environ, SERVER_ENV: str(server)},
                           stderr=subprocess.PIPE, text=True)
    _wait(lambda: pid_file.exists() and pid_file.read_text(), "the job did not start")
    os.kill(int(pid_file.read_text()), signal.SIGKILL)
    _, err = job.communicate(timeout=60)
    assert job.returncode == 128 + signal.SIGKILL, err
    line = log.read_text().strip()
    assert line.startswith("alfa-bench: detect job sleep-job: the job's process was killed "
                           "by SIGKILL (Killed): most likely the kernel's out-of-memory "
                           "killer"), line
    assert line in err


def test_without_a_server_a_job_runs_in_its_own_process(tmp_path):
    assert client(tmp_path / "none.sock", "echo").returncode == 99
    # the rule's command: a socket that is gone, so the job runs here, and meets its
    # arguments' error itself
    done = subprocess.run([sys.executable, "-m", "alfa_bench.workflow.detect_job"],
                          env={**os.environ, SERVER_ENV: str(tmp_path / "none.sock")},
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and "the following arguments are required" in done.stderr


def test_the_server_stops_when_its_workflow_is_gone(tmp_path):
    """Its parent, Snakemake, killed: the server leaves, and takes its socket."""
    path = tmp_path / "s.sock"
    parent = subprocess.Popen([sys.executable, "-c", (
        "import subprocess, sys, os, time; "
        f"subprocess.Popen([sys.executable, {str(TESTS / 'forkserver_jobs.py')!r}, "
        f"{str(path)!r}, str(os.getpid())]); time.sleep(60)")])
    _wait(path.exists, "the server did not listen")
    parent.kill()
    parent.wait()
    _wait(lambda: not path.exists(), "the server outlived its workflow")


def test_started_and_stopped_by_the_workflow_with_one_thread_per_job(tmp_path):
    """`start` names the socket in the environment once the server listens, with the
    numerical libraries at one thread (as Snakemake sets them for a job); `stop` ends
    it and forgets the name."""
    config = tmp_path / "config.json"
    config.write_text(json.dumps({"methods": {}}))
    env = "ALFA_BENCH_TEST_SERVER"
    path = forkserver.start(env, "alfa_bench.workflow.detect_job:server_jobs", [config],
                            tmp_path / "server.log")
    try:
        assert os.environ[env] == path and os.path.exists(path)
        (server,) = forkserver._SERVERS.values()
        environ = Path(f"/proc/{server.pid}/environ").read_bytes().split(b"\0")
        assert b"OPENBLAS_NUM_THREADS=1" in environ and b"OMP_NUM_THREADS=1" in environ
    finally:
        forkserver.stop(env)
    assert env not in os.environ and not os.path.exists(path)
    assert server.poll() is not None


def test_two_configs_never_share_the_file_their_jobs_read(tmp_path, monkeypatch):
    """A dry run of another config beside a run writes a file of its own: the running
    jobs still read theirs; the file's name is not in the jobs' command, so a config
    change re-runs only the jobs whose parameters changed."""
    monkeypatch.delenv(CONFIG_ENV, raising=False)
    first = write_job_config({"methods": {"a": {}}}, tmp_path)
    assert os.environ[CONFIG_ENV] == str(first.resolve())
    second = write_job_config({"methods": {"b": {}}}, tmp_path)
    assert second != first and os.environ[CONFIG_ENV] == str(second.resolve())
    assert json.loads(first.read_text()) == {"methods": {"a": {}}}
    assert write_job_config({"methods": {"a": {}}}, tmp_path) == first
