"""A one-node SLURM cluster with accounting, brought up in a folder and torn down again.

munge, a private MariaDB on loopback, slurmdbd, slurmctld and slurmd run in the
foreground as children of the test, with every file (keys, sockets, state, logs) under
one folder, so that nothing of the machine's own configuration is read or changed. The
configuration is ``tests/slurm/slurm.conf`` and ``tests/slurm/slurmdbd.conf``.
"""

import csv
import getpass
import importlib.util
import os
import shutil
import socket
import subprocess
import threading
import time
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import yaml

__all__ = ["ACCOUNT", "PARTITION", "SlurmRun", "running", "slurm_cluster", "slurm_profile",
           "slurm_unavailable", "through_slurm"]

CONFIGS = Path(__file__).parent / "slurm"
DAEMONS = ("munged", "mariadbd", "slurmdbd", "slurmctld", "slurmd")
CLIENTS = ("mariadb-install-db", "mariadb", "sacctmgr", "sbatch", "sacct", "sinfo", "srun",
           "squeue", "scancel", "scontrol")
ACCOUNT = "alfa-test"
PARTITION = "test"
#: loopback ports, away from SLURM's and MariaDB's defaults in case those run here
PORTS = {"ctld_port": 16817, "slurmd_port": 16818, "dbd_port": 16819, "db_port": 16306}


def slurm_unavailable() -> str | None:
    """Why no cluster can be brought up here, or None."""
    missing = [p for p in (*DAEMONS, *CLIENTS) if not Path(_program(p)).exists()]
    if missing:
        return (f"SLURM is not installed here (no {', '.join(missing)}): .ci/run installs "
                "Debian's slurmctld slurmd slurmdbd slurm-client munge mariadb-server")
    if os.geteuid() != 0:
        return "the test cluster's daemons run as root, and this is not root"
    if importlib.util.find_spec("snakemake_executor_plugin_slurm") is None:
        return "snakemake-executor-plugin-slurm is not installed (the `cluster` extra)"
    return None


def _program(name: str) -> str:
    return shutil.which(name) or str(Path("/usr/sbin", name))


def _wait(what: str, ready, log: Path, timeout_s: float = 60.0) -> None:
    """Poll ``ready()`` until it holds; on time-out, fail with the daemon's log."""
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if ready():
            return
        time.sleep(0.25)
    tail = log.read_text(errors="replace")[-3000:] if log.exists() else "(no log)"
    raise RuntimeError(f"{what} did not come up within {timeout_s:.0f} s; {log}:\n{tail}")


def _succeeds(*cmd: str, env: dict | None = None) -> bool:
    return subprocess.run(cmd, env=env, capture_output=True).returncode == 0


@contextmanager
def slurm_cluster(root: Path):
    """Bring the cluster up under ``root``; yield the environment its clients need.

    The environment sets ``SLURM_CONF`` and puts a job-step ``srun`` first on PATH; the
    account :data:`ACCOUNT` is registered for the current user on partition
    :data:`PARTITION`. On exit every job is cancelled and every daemon stopped (in
    reverse order of start); :func:`running` tells whether any process outlived them.
    """
    host = socket.gethostname().split(".")[0]
    for sub in ("munge", "state", "spool", "run", "log", "db"):
        (root / sub).mkdir(parents=True, exist_ok=True)
    fill = {"root": root, "host": host, "cpus": os.cpu_count(),
            "memory_mb": _memory_mb(), **PORTS}
    conf = root / "slurm.conf"
    conf.write_text((CONFIGS / "slurm.conf").read_text().format(**fill))
    dbd_conf = root / "slurmdbd.conf"
    dbd_conf.write_text((CONFIGS / "slurmdbd.conf").read_text().format(**fill))
    dbd_conf.chmod(0o600)                 # slurmdbd refuses a readable password file
    key = root / "munge/munge.key"
    key.write_bytes(os.urandom(1024))
    key.chmod(0o600)
    env = {**os.environ, "SLURM_CONF": str(conf), "PATH": _step_shim(root, conf)}
    log = root / "log"
    procs: list[subprocess.Popen] = []

    def start(*cmd, name: str) -> None:
        with open(log / f"{name}.out", "w") as out:
            procs.append(subprocess.Popen(cmd, env=env, stdout=out,
                                          stderr=subprocess.STDOUT, start_new_session=True))

    sock = root / "munge/munge.socket"
    db_sock = root / "db.sock"
    try:
        start(_program("munged"), "--foreground", "--force", f"--key-file={key}",
              f"--socket={sock}", f"--pid-file={root}/run/munged.pid",
              f"--log-file={log}/munged.log", f"--seed-file={root}/munge/seed",
              name="munged")
        _wait("munged", sock.exists, log / "munged.log")

        subprocess.run([_program("mariadb-install-db"), "--no-defaults",
                        f"--datadir={root}/db", "--user=root", "--skip-test-db",
                        "--auth-root-authentication-method=socket"],
                       env=env, capture_output=True, check=True)
        start(_program("mariadbd"), "--no-defaults", f"--datadir={root}/db",
              f"--socket={db_sock}", f"--port={PORTS['db_port']}",
              "--bind-address=127.0.0.1", "--user=root", f"--log-error={log}/mariadb.log",
              "--innodb-buffer-pool-size=256M", "--innodb-lock-wait-timeout=900",
              name="mariadbd")
        _wait("mariadbd", db_sock.exists, log / "mariadb.log")
        sql = ("CREATE USER 'slurm'@'127.0.0.1' IDENTIFIED BY 'slurm';"
               "GRANT ALL ON slurm_acct_db.* TO 'slurm'@'127.0.0.1';")
        subprocess.run([_program("mariadb"), "--no-defaults", f"--socket={db_sock}",
                        "-u", "root", "-e", sql], env=env, capture_output=True, check=True)

        # slurmdbd takes no -f: it reads slurmdbd.conf beside SLURM_CONF
        start(_program("slurmdbd"), "-D", name="slurmdbd")
        _wait("slurmdbd", lambda: _succeeds("sacctmgr", "-n", "list", "cluster", env=env),
              log / "slurmdbd.log")
        for args in (("cluster", "alfa-test"), ("account", ACCOUNT, "cluster=alfa-test"),
                     ("user", getpass.getuser(), f"account={ACCOUNT}", "cluster=alfa-test")):
            subprocess.run(["sacctmgr", "-i", "add", *args], env=env, capture_output=True,
                           check=True)

        start(_program("slurmctld"), "-D", "-c", "-i", "-f", str(conf), name="slurmctld")
        _wait("slurmctld", lambda: _succeeds("scontrol", "ping", env=env),
              log / "slurmctld.log")
        start(_program("slurmd"), "-D", "-f", str(conf), "-N", host, name="slurmd")
        _wait("slurmd", lambda: _idle(env), log / "slurmd.log")
        yield env
    finally:
        subprocess.run(["scancel", "--user", getpass.getuser()], env=env,
                       capture_output=True)
        for proc in reversed(procs):      # slurmd first, munged last
            proc.terminate()
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def slurm_profile(profile: Path, dest: Path) -> Path:
    """A copy of the project's SLURM profile for the test cluster: its account and
    partition, the first status check after 1 s rather than 40 (the jobs here take
    seconds), and every job's SLURM log kept, not only a failed one's."""
    config = yaml.safe_load((profile / "config.yaml").read_text())
    config["default-resources"].update(slurm_account=ACCOUNT, slurm_partition=PARTITION)
    config["slurm-init-seconds-before-status-checks"] = 1
    config["slurm-keep-successful-logs"] = True
    dest.mkdir(parents=True, exist_ok=True)
    (dest / "config.yaml").write_text(yaml.safe_dump(config))
    return dest


@dataclass
class SlurmRun:
    """A workflow run through the test cluster, and what SLURM recorded of it."""

    workdir: Path
    done: subprocess.CompletedProcess
    accounting: list[dict]      # sacct: one row per job (JobID, Comment, State, ...)
    killed: dict | None         # the job killed once while it ran (JobID, Comment)
    left_running: list[str]     # the cluster's processes still alive after it stopped


def through_slurm(root: Path, workdir: Path, prefix: str,
                  run: Callable[[dict], subprocess.CompletedProcess]) -> SlurmRun:
    """Bring the cluster up under ``root``, call ``run(env)`` while the first running job
    whose comment starts with ``prefix`` is killed once, read the accounting, and stop
    the cluster.

    The job's batch script is sent SIGKILL, as the kernel's out-of-memory killer or a
    crash would end it, and SLURM records it FAILED. (``scancel`` proper is no test of
    a retry: SLURM then records "CANCELLED by <uid>", which the executor plugin 2.8
    takes for a running job, so the run waits for ever; docs/speed.md.)"""
    with slurm_cluster(root) as env:
        stop, killed = threading.Event(), {}
        killer = threading.Thread(target=_kill_one, args=(env, prefix, stop, killed))
        killer.start()
        try:
            done = run(env)
        finally:
            stop.set()
            killer.join()
        accounting = _sacct(env)
    return SlurmRun(workdir, done, accounting, killed or None, running(root))


def _kill_one(env: dict, prefix: str, stop: threading.Event, killed: dict) -> None:
    while not stop.wait(0.2):
        queue = subprocess.run(["squeue", "-h", "-o", "%i|%k|%T"], env=env,
                               capture_output=True, text=True).stdout
        for line in queue.splitlines():
            job, comment, state = line.split("|")
            if comment.startswith(prefix) and state == "RUNNING":
                subprocess.run(["scancel", "--signal=KILL", "--batch", job], env=env,
                               check=True)
                killed.update(JobID=job, Comment=comment)
                return


def _sacct(env: dict) -> list[dict]:
    """Every job of the cluster's life, from slurmdbd (its records land within seconds)."""
    fields = ["JobID", "JobName", "Comment", "Account", "Partition", "State", "ExitCode",
              "Elapsed", "ReqMem", "Timelimit"]
    for _ in range(40):
        out = subprocess.run(["sacct", "-a", "-X", "-P", "-S", "now-1days", "-o",
                              ",".join(fields)], env=env, capture_output=True, text=True,
                             check=True).stdout
        rows = list(csv.DictReader(out.splitlines(), delimiter="|"))
        if rows and not any(r["State"] in {"PENDING", "RUNNING"} for r in rows):
            return rows
        time.sleep(0.5)
    return rows


def _step_shim(root: Path, conf: Path) -> str:
    """PATH with an ``srun`` first that finds this cluster's configuration.

    Snakemake's jobstep executor clears every ``SLURM_*`` variable but the job's identity
    before it calls ``srun`` inside a job, so ``SLURM_CONF`` does not reach it; a real
    cluster's nodes read ``/etc/slurm/slurm.conf`` instead, which this cluster leaves alone.
    """
    bin_dir = root / "bin"
    bin_dir.mkdir(exist_ok=True)
    shim = bin_dir / "srun"
    shim.write_text(f'#!/bin/sh\nSLURM_CONF="{conf}" exec {shutil.which("srun")} "$@"\n')
    shim.chmod(0o755)
    return f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}"


def running(root: Path) -> list[str]:
    """The command lines of the cluster's processes still alive: those whose command
    line or environment names ``root`` (every daemon was started with ``SLURM_CONF``
    there, and job steps and scripts inherit it), and any ``slurmstepd``."""
    alive = []
    for proc in Path("/proc").glob("[0-9]*"):
        try:
            cmd = (proc / "cmdline").read_bytes().replace(b"\0", b" ").decode().strip()
            environ = (proc / "environ").read_bytes()
        except OSError:
            continue
        if not cmd or proc.name == str(os.getpid()):
            continue
        if (str(root) in cmd or str(root).encode() in environ
                or cmd.startswith("slurmstepd")):
            alive.append(cmd)
    return alive


def _idle(env: dict) -> bool:
    done = subprocess.run(["sinfo", "-h", "-o", "%t"], env=env, capture_output=True,
                          text=True)
    return done.returncode == 0 and done.stdout.strip() == "idle"


def _memory_mb() -> int:
    """The node's memory for SLURM: what the machine has, less 1 GB for the daemons."""
    total_kb = int(Path("/proc/meminfo").read_text().split()[1])
    return total_kb // 1024 - 1024
