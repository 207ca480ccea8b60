"""A fork server with test jobs, for tests/test_forkserver.py:

    python tests/forkserver_jobs.py <socket> <parent pid>

A job's first argument names what it does; ``prepare`` counts in the server the jobs
it prepared, which a job prints, so that the tests see the server's state reach the
forks."""

import os
import subprocess
import sys
import time

from alfa_bench.workflow.detect_job import parse
from alfa_bench.workflow.forkserver import serve

prepared = []


def prepare(argv):
    if argv[0] == "bad-prepare":
        raise RuntimeError("prepare failed")
    prepared.append(argv[0])
    return argv[0] != "refused"


def handle(argv):
    match argv[0]:
        case "echo":
            print("out:", *argv[1:], f"prepared {len(prepared)}")
            print("err:", *argv[1:], file=sys.stderr)
        case "fail" | "bad-prepare":
            raise ValueError("the job failed")
        case "exit":
            sys.exit(int(argv[1]))
        case "child-status":         # the job's own subprocess's exit status
            print(subprocess.run(["false"]).returncode)
        case "sleep":                # writes its pid, then runs until killed
            with open(argv[1], "w") as f:
                f.write(str(os.getpid()))
            time.sleep(60)
        case "sleep-job":            # a detect job's arguments: its pid in its benchmark
            with open(parse(argv).benchmark, "w") as f:
                f.write(str(os.getpid()))
            time.sleep(60)
        case "crash":
            os._exit(0)              # gone without a status


if __name__ == "__main__":
    serve(sys.argv[1], lambda: None, prepare, handle, int(sys.argv[2]))
