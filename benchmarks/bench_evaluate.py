"""The researcher's loop against the workflow's: one configured run scored from Python
(a fresh process: import, the cached corpus, evaluate) beside `snakemake all` after a
change to that run (its detect job and every table after it run again), in turns.

    ALFA_DIR=/path/to/alfa .venv/bin/python benchmarks/bench_evaluate.py [--run NAME] [-n 3]

Run it in a checkout whose results/ is complete (after `snakemake all`); the corpus's
cache is filled by a first, uncounted call.
"""

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def timed(cmd: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(cmd, cwd=REPO, check=True, capture_output=True)
    return time.perf_counter() - start


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--run", default="residual_bank")
    p.add_argument("-n", type=int, default=3)
    args = p.parse_args()
    loop = [sys.executable, "-c", "import alfa_bench as ab; "
            f"ab.evaluate({args.run!r}, ab.load_corpus())"]
    workflow = [sys.executable, "-m", "snakemake", "all", "--cores", "2", "--quiet",
                "--forcerun", f"results/detections/{args.run}"]
    timed(loop)                                   # fills the corpus's cache
    pairs = [(timed(loop), timed(workflow)) for _ in range(args.n)]
    a, b = zip(*pairs, strict=True)
    print(f"evaluate({args.run!r}), fresh process: median {statistics.median(a):.1f} s "
          f"({min(a):.1f}-{max(a):.1f})")
    print(f"snakemake all after a change to {args.run}: median {statistics.median(b):.1f} s "
          f"({min(b):.1f}-{max(b):.1f})")
    print(f"ratio workflow / evaluate, pair by pair: median "
          f"{statistics.median(y / x for x, y in pairs):.1f}")


if __name__ == "__main__":
    main()
