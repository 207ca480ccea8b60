"""The jobs' fork servers: the imports (and for the detect jobs, the flights) loaded once
per run of the workflow, each job a fork of them. The detect jobs have one
(:mod:`.detect_job`), the runs' parts jobs another (:mod:`.parts_job`).

A detect job started as a process of its own pays 1-2 s before its detector runs: the
imports (numpy, pandas, scipy, scikit-learn, numba's kernels, the configured library
models, matplotlib) and the cached flights and manifests. On one machine the workflow
starts this server before its first job (:func:`start`, from ``onstart``) and names
its socket in the environment (:data:`~.detect_job.SERVER_ENV`). A detect job's
command is then a client (:func:`submit`): it sends the server its arguments and its
standard output and error, and waits. The server loads what the job reads, if not yet
loaded (:func:`~.detect_job.prepare`), and forks; the child, sharing the loaded modules
and flights copy-on-write, runs the job as it would run alone
(:func:`~.detect_job.forked`), writes its output to the client's streams, and sends
its exit status back, which becomes the client's. A client killed by Snakemake takes
its child with it. A child killed by a signal (the kernel's out-of-memory killer
sends SIGKILL) sends nothing: the fork between the server and it, which waits for it,
sends the signal instead, and the client names it (:func:`killed`).

The server knows nothing of what it runs: :func:`start` names a function that returns
the three steps (for the detect jobs, :func:`~.detect_job.server_jobs`), which the
server's process imports.

Where no server answers (a cluster executor, which starts none; a server gone), the
client runs the job in its own process: the same function, the same files.

The server stops with the Snakemake process that started it (:func:`stop`, from
``onsuccess`` and ``onerror``, else when that process is gone).
"""

from __future__ import annotations

import importlib
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import traceback
from pathlib import Path

__all__ = ["changed_since", "imported_sources", "killed", "run_job", "serve", "start",
           "stop", "submit"]

_STARTED, _EXITED = b"+", b"="
#: the threads of the numerical libraries, fixed when they load: one, as Snakemake
#: sets them for a job of one thread (a detect job's)
_ONE_THREAD = dict.fromkeys(["OMP_NUM_THREADS", "GOTO_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                             "MKL_NUM_THREADS", "VECLIB_MAXIMUM_THREADS",
                             "NUMEXPR_NUM_THREADS"], "1")
#: the servers this process started, by socket path
_SERVERS: dict[str, subprocess.Popen] = {}
#: what a signal that ends a job most likely means
_MEANINGS = {
    signal.SIGKILL: "most likely the kernel's out-of-memory killer (`dmesg` names the "
                    "process it killed): give the job more memory (its rule's mem_mb) or "
                    "run fewer jobs at once (--cores)",
    signal.SIGSEGV: "a crash in compiled code (numba's, a library's)",
    signal.SIGBUS: "a crash in compiled code, or a file it had mapped was cut short",
    signal.SIGTERM: "stopped from outside: the workflow interrupted, or a time limit",
    signal.SIGINT: "interrupted (Ctrl-C)",
}


def imported_sources(package: str = "alfa_bench") -> dict[str, int]:
    """The modification time of the file of each module of ``package`` this process
    imported, by file: what a server's preload loaded (:func:`changed_since`)."""
    times = {}
    for name, module in list(sys.modules.items()):
        path = getattr(module, "__file__", None)
        if name.startswith(package) and path:
            try:
                times[path] = os.stat(path).st_mtime_ns
            except OSError:
                times[path] = -1
    return times


def changed_since(sources: dict[str, int]) -> bool:
    """Whether a file of ``sources`` (:func:`imported_sources`) changed since: a job
    forked now would run the old code, and its outputs, newer than the change, would
    never be re-run."""
    return any(os.stat(p).st_mtime_ns != t if os.path.exists(p) else True
               for p, t in sources.items())


def killed(signum: int) -> str:
    """A line naming signal ``signum``, which ended a job's process, and what it most
    likely means."""
    try:
        name = signal.Signals(signum).name
    except ValueError:
        name = f"signal {signum}"
    return (f"the job's process was killed by {name} ({signal.strsignal(signum)}): "
            + _MEANINGS.get(signum, "sent from outside the job"))


def submit(path: str, argv: list[str]) -> int | None:
    """Run the job of ``argv`` on the server at ``path``, with this process's standard
    output and error: its exit status (the negative number of the signal that killed
    it, as :mod:`subprocess` gives), or None when no server took it (the caller runs it
    itself)."""
    client = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        client.connect(path)
    except OSError:
        client.close()
        return None
    with client:
        data = json.dumps({"cwd": os.getcwd(), "argv": argv}).encode()
        socket.send_fds(client, [len(data).to_bytes(4, "big") + data],
                        [sys.stdout.fileno(), sys.stderr.fileno()])
        reply = b""
        while chunk := client.recv(64):
            reply += chunk
    if not reply.startswith(_STARTED):
        return None                  # the server went before it forked: nothing ran
    if _EXITED not in reply:
        print(f"alfa-bench: the job's process (forked by the server at {path}) "
              "ended without an exit status; see the job's log", file=sys.stderr)
        return 1
    return int(reply.split(_EXITED)[1])


def run_job(env: str, kind: str, argv: list[str], parse, run) -> int:
    """A job's command: run the job of ``argv`` on the server named in the environment
    variable ``env`` when one answers, else here (``run(parse(argv))``); its exit
    status. A job killed by a signal is named, as a ``kind`` job, in its log (the
    ``log`` of ``parse(argv)``) and on standard error."""
    server = os.environ.get(env)
    if server:
        status = submit(server, argv)
        if status is not None and status < 0:
            # the fork could write nothing: its log says what ended it; the status is
            # the shell's for a process killed by a signal
            args = parse(argv)
            line = f"alfa-bench: {kind} job {args.method}: {killed(-status)}"
            with open(args.log, "a") as log:
                print(line, file=log)
            print(line, file=sys.stderr)
            return 128 - status
        if status is not None:
            return status
    run(parse(argv))
    return 0


def _receive(conn: socket.socket) -> tuple[str, list[str], list[int]]:
    """A client's working folder, arguments, and output and error streams."""
    data, fds, _, _ = socket.recv_fds(conn, 65536, 2)
    size = int.from_bytes(data[:4], "big")
    data = data[4:]
    while len(data) < size:
        more = conn.recv(size - len(data))
        if not more:
            raise ConnectionError("the client closed before sending its arguments")
        data += more
    request = json.loads(data)
    return request["cwd"], request["argv"], fds


def _watch(conn: socket.socket, argv: list[str], fds: list[int], handle) -> None:
    """In the server's fork: the job in a fork of this one, waited for, so that a
    signal that kills it (it can send no status then) reaches the client. The server
    lets the kernel reap its forks, and so cannot learn how they ended."""
    signal.signal(signal.SIGCHLD, signal.SIG_DFL)    # this fork's, and the job's own
    conn.sendall(_STARTED)
    pid = os.fork()
    if pid == 0:
        _child(conn, argv, fds, handle)
    for fd in fds:
        os.close(fd)
    _, status = os.waitpid(pid, 0)
    if os.WIFSIGNALED(status):
        try:
            conn.sendall(_EXITED + str(-os.WTERMSIG(status)).encode())
        except OSError:
            pass                     # the client is gone too
    os._exit(0)


def _child(conn: socket.socket, argv: list[str], fds: list[int], handle) -> None:
    """In the job's fork: the client's streams as this process's, the job, its status."""
    os.dup2(fds[0], 1)
    os.dup2(fds[1], 2)
    for fd in fds:
        os.close(fd)

    def watch():                     # the client gone (Snakemake killed the job): stop
        if not conn.recv(1):
            os._exit(1)

    threading.Thread(target=watch, daemon=True).start()
    status = 0
    try:
        handle(argv)
    except SystemExit as e:          # argparse's usage error, and sys.exit in a job
        status = e.code if isinstance(e.code, int) else 1
    except BaseException:
        sys.excepthook(*sys.exc_info())      # the job's log gets it, as when run alone
        status = 1
    finally:
        import logging

        logging.shutdown()
        sys.stdout.flush()
        sys.stderr.flush()
        try:
            conn.sendall(_EXITED + str(status).encode())
        finally:
            os._exit(status)


def serve(path: str, preload, prepare, handle, parent: int) -> None:
    """Serve jobs on the Unix socket ``path`` until process ``parent`` is gone:
    ``preload()`` once, then for each client ``prepare(argv)`` here (what the jobs
    share; a failure is left for the job to meet), and ``handle(argv)`` in a fork, with
    the client's streams. A client is left to run its job itself (nothing is sent to
    it) when it works in another folder than the server's (another workflow's job), or
    when ``prepare`` returns False (the server's code is no longer the job's). It
    listens before it preloads, so that a job never finds the
    socket missing: the first jobs wait for the preload instead."""
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listener.bind(path)
    listener.listen(64)
    listener.settimeout(1.0)
    signal.signal(signal.SIGCHLD, signal.SIG_IGN)    # the kernel reaps the forks
    try:
        preload()
        while os.getppid() == parent and os.path.exists(path):
            try:
                conn, _ = listener.accept()
            except TimeoutError:
                continue
            with conn:
                conn.settimeout(None)
                try:
                    cwd, argv, fds = _receive(conn)
                except (OSError, ValueError, KeyError) as e:
                    print(f"a client's request could not be read: {e}", file=sys.stderr)
                    continue
                try:
                    taken = cwd == os.getcwd() and prepare(argv) is not False
                except Exception:
                    traceback.print_exc()    # the job meets it again, in its own log
                    taken = True
                if not taken:
                    for fd in fds:
                        os.close(fd)
                    continue
                if os.fork() == 0:
                    listener.close()
                    _watch(conn, argv, fds, handle)
                for fd in fds:
                    os.close(fd)
    finally:
        listener.close()
        Path(path).unlink(missing_ok=True)


def start(env: str, jobs: str, args: list[str], log: str | Path,
          wait_s: float = 10.0) -> str:
    """Start a server (its output to ``log``) for the jobs that ``jobs``, a function
    named ``"module:function"``, sets up when called with ``args`` in the server's
    process: it returns the three steps of :func:`serve`, ``(preload, prepare,
    handle)``. Name the server's socket in this process's environment variable ``env``,
    which the jobs inherit. Returns the socket's path once the server listens on it."""
    path = os.path.join(tempfile.mkdtemp(prefix="alfa-bench-"), "detect.sock")
    Path(log).parent.mkdir(parents=True, exist_ok=True)
    with open(log, "w") as out:
        _SERVERS[path] = subprocess.Popen(
            [sys.executable, "-m", "alfa_bench.workflow.forkserver", path, str(os.getpid()),
             jobs, *map(str, args)], stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
            env={**os.environ, **_ONE_THREAD})
    deadline = time.monotonic() + wait_s
    while not os.path.exists(path) and time.monotonic() < deadline:
        if _SERVERS[path].poll() is not None:
            break
        time.sleep(0.02)
    if os.path.exists(path):
        os.environ[env] = path
    return path


def stop(env: str) -> None:
    """Stop the servers this process started, and forget ``env``."""
    os.environ.pop(env, None)
    for path, server in list(_SERVERS.items()):
        server.terminate()
        server.wait()
        Path(path).unlink(missing_ok=True)
        Path(path).parent.rmdir()
        del _SERVERS[path]


def _main(path: str, parent: str, jobs: str, *args: str) -> None:
    module, _, function = jobs.partition(":")
    preload, prepare, handle = getattr(importlib.import_module(module), function)(*args)
    serve(path, preload, prepare, handle, int(parent))


if __name__ == "__main__":
    _main(*sys.argv[1:])
