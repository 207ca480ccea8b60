"""Wall time of ``snakemake all --cores 2`` from a clean ``results/``, and how it grows.

    ALFA_DIR=/path/to/alfa .venv/bin/python benchmarks/bench_workflow.py \
        [--flights 1 2 4] [--settings 1 4 16]

- ``--flights``: the flights of ``$ALFA_DIR/processed`` replicated k times (copies are
  symlinks under new names on the same dates, so the leave-one-day-out folds stay
  the same and each fold calibrates on k times the data), every configured method.
- ``--settings``: the configured methods plus k settings of ``glrt_arx`` (its
  false-alarm probability swept), over the flights once.
- ``--changed``: the run over the flights once, then ``glrt_arx_chi2``'s false-alarm
  probability halved and ``snakemake all`` again: the re-run's wall time and the jobs it
  ran, per rule.

Each case runs in a fresh temporary working directory; prints a Markdown table.
"""

from __future__ import annotations

import argparse
import copy
import os
import re
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
_FINISHED = re.compile(r"^Finished jobid: \d+ \(Rule: (\w+)\)$", re.M)
_TIME = re.compile(r"^(carbonZ_\d{4}-\d{2}-\d{2}-)(\d{2})(-\d{2}-\d{2}.*)$")


def replicate(processed: Path, dest: Path, copies: int) -> int:
    """Symlink every flight of ``processed`` ``copies`` times into ``dest``; copy r moves
    the recording hour by r. The hour keeps two digits up to 99 (ALFA's flights are
    recorded from 11 to 17 h), so names stay parseable; a clash with another flight's
    name is an error."""
    n = 0
    for flight in sorted(p for p in processed.iterdir() if p.is_dir()):
        for r in range(copies):
            m = _TIME.match(flight.name)
            name = f"{m[1]}{int(m[2]) + r:02d}{m[3]}"
            folder = dest / name
            folder.mkdir(parents=True)
            for f in flight.iterdir():
                (folder / f.name.replace(flight.name, name, 1)).symlink_to(f.resolve())
            n += 1
    return n


def run(alfa: Path, config: Path, work: Path) -> tuple[float, Counter]:
    """The wall time of ``snakemake all`` and the jobs it ran, counted per rule."""
    cmd = [sys.executable, "-m", "snakemake", "all", "--cores", "2",
           "--snakefile", str(ROOT / "Snakefile"), "--directory", str(work),
           "--configfile", str(config)]
    t = time.perf_counter()
    done = subprocess.run(cmd, env={**os.environ, "ALFA_DIR": str(alfa)},
                          capture_output=True, text=True)
    wall = time.perf_counter() - t
    if done.returncode:       # the working directory, logs and all, goes with the run
        sys.exit(f"snakemake failed in {work}:\n{done.stderr[-5000:]}")
    return wall, Counter(_FINISHED.findall(done.stderr))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--flights", type=int, nargs="*", default=[1, 2, 4])
    ap.add_argument("--settings", type=int, nargs="*", default=[1, 4, 16])
    ap.add_argument("--changed", action="store_true")
    args = ap.parse_args()
    processed = Path(os.environ["ALFA_DIR"]) / "processed"
    base = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    found = sum(1 for p in processed.iterdir() if p.is_dir())
    print("| case | flights found | method runs | wall s |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        config = tmp / "config.yaml"
        config.write_text(yaml.safe_dump(base))
        for k in args.flights:
            alfa = tmp / f"alfa{k}"
            n = replicate(processed, alfa / "processed", k)
            wall, _ = run(alfa, config, tmp / f"flights{k}")
            print(f"| flights x{k} | {n} | {len(base['methods'])} | {wall:.1f} |", flush=True)
        for k in args.settings:
            swept = dict(base)
            swept["methods"] = {**base["methods"], **{
                f"glrt_arx_pf{i}": {"detector": "glrt_residuals", "params": {
                    **base["methods"]["glrt_arx"]["params"],
                    "false_alarm": 1e-4 * (i + 1)}} for i in range(k)}}
            config = tmp / f"config{k}.yaml"
            config.write_text(yaml.safe_dump(swept))
            wall, _ = run(processed.parent, config, tmp / f"settings{k}")
            print(f"| glrt_arx settings x{k} | {found} | {len(swept['methods'])} | {wall:.1f} |",
                  flush=True)
        if args.changed:
            config = tmp / "changed.yaml"
            config.write_text(yaml.safe_dump(base))
            wall, _ = run(processed.parent, config, tmp / "changed")
            print(f"| all, before the change | {found} | {len(base['methods'])} | {wall:.1f} |")
            changed = copy.deepcopy(base)
            changed["methods"]["glrt_arx_chi2"]["params"]["false_alarm"] /= 2
            config.write_text(yaml.safe_dump(changed))
            wall, jobs = run(processed.parent, config, tmp / "changed")
            ran = ", ".join(f"{rule} {k}" for rule, k in sorted(jobs.items()))
            print(f"| all, after glrt_arx_chi2 changed ({ran}) | {found} | "
                  f"{len(base['methods'])} | {wall:.1f} |", flush=True)


if __name__ == "__main__":
    main()
