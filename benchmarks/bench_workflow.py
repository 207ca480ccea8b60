"""Wall time of ``snakemake all --cores 2`` from a clean ``results/``, and how it grows.

    ALFA_DIR=/path/to/alfa .venv/bin/python benchmarks/bench_workflow.py \
        [--flights 1 2 4] [--settings 1 4 16] [--changed] [--extra 7] [--root DIR]

- ``--flights``: the flights of ``$ALFA_DIR/processed`` replicated k times (copies are
  symlinks under new names on the same dates, so the leave-one-day-out folds stay
  the same and each fold calibrates on k times the data), every configured method.
- ``--settings``: the configured methods plus k settings of ``glrt_arx`` (its
  false-alarm probability swept), over the flights once.
- ``--changed``: the run over the flights once, then ``glrt_arx_chi2``'s false-alarm
  probability halved and ``snakemake all`` again: the re-run's wall time and the jobs it
  ran, per rule; and the size of the first run's ``results/``, by folder. With
  ``--changes N``, halved N times, each time run again; with ``--against DIR``, the
  same on the workflow of another checkout (as ``--root``), each change run on both in
  turns, the order swapped each time: before and after on the same stretch of the
  machine.
- ``--extra N``: every corpus also holds N more copies (every sixth flight, recorded
  three hours later on its date): ``--extra 7`` makes the 40 local flights a corpus of
  ALFA's 47.
- ``--root DIR``: run the workflow (Snakefile, config) of another checkout, with the
  Python of its ``.venv``: the same cases, timed on older code in the same session.
- ``--methods-of DIR``, ``--targets RULE ...``: keep only the method runs of another
  checkout's config, and run these rules instead of ``all``, so that two commits with
  different runs and products can be timed on the same work.
- ``--stored``: the run over the flights once, then ``results/`` removed but for the
  fits the detect jobs keep (``results/fits``) and ``snakemake all`` again: both wall
  times, the fits' size, and the second run's cost table.
- ``--costs DIR``: only print the cost table of the workflow run in ``DIR`` (its
  ``results/benchmarks/detect``), running nothing.

Each case runs in a fresh temporary working directory; prints a Markdown table of wall
times, then the wall time and peak resident memory of each job of each run from empty
that keeps a Snakemake benchmark file, and the cost table of each: per run, the fits
made, kept in the job, and read from ``results/fits``, and the seconds spent fitting,
scoring, on features, reading and writing (``workflow/job_costs.py`` says what each
counts).
"""

from __future__ import annotations

import argparse
import copy
import csv
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import yaml

_FINISHED = re.compile(r"^Finished jobid: \d+ \(Rule: (\w+)\)$", re.M)
_TIME = re.compile(r"^(carbonZ_\d{4}-\d{2}-\d{2}-)(\d{2})(-\d{2}-\d{2}.*)$")


def _link(flight: Path, dest: Path, shift_h: int) -> None:
    m = _TIME.match(flight.name)
    name = f"{m[1]}{int(m[2]) + shift_h:02d}{m[3]}"
    folder = dest / name
    folder.mkdir(parents=True)       # a clash with another flight's name is an error
    for f in flight.iterdir():
        (folder / f.name.replace(flight.name, name, 1)).symlink_to(f.resolve())


def replicate(processed: Path, dest: Path, copies: int, extra: int = 0) -> int:
    """Symlink every flight of ``processed`` ``copies`` times into ``dest``; copy r moves
    the recording hour by r. Then ``extra`` more: every sixth flight, moved by
    ``copies + 2`` hours. The hour keeps two digits up to 99 (ALFA's flights are
    recorded from 11 to 17 h), so names stay parseable."""
    flights = sorted(p for p in processed.iterdir() if p.is_dir())
    for flight in flights:
        for r in range(copies):
            _link(flight, dest, r)
    for flight in flights[::6][:extra]:
        _link(flight, dest, copies + 2)
    return len(flights) * copies + min(extra, len(flights[::6]))


def run(root: Path, alfa: Path, config: Path, work: Path, targets=("all",)
        ) -> tuple[float, Counter]:
    """The wall time of ``snakemake <targets>`` and the jobs it ran, counted per rule."""
    python = root / ".venv/bin/python"
    cmd = [str(python) if python.exists() else sys.executable, "-m", "snakemake", *targets,
           "--cores", "2", "--snakefile", str(root / "Snakefile"), "--directory", str(work),
           "--configfile", str(config)]
    t = time.perf_counter()
    done = subprocess.run(cmd, env={**os.environ, "ALFA_DIR": str(alfa)},
                          capture_output=True, text=True)
    wall = time.perf_counter() - t
    if done.returncode:       # the working directory, logs and all, goes with the run
        sys.exit(f"snakemake failed in {work}:\n{done.stderr[-5000:]}")
    return wall, Counter(_FINISHED.findall(done.stderr))


def job_stats(work: Path) -> dict[str, tuple[float, float]]:
    """Per job with a Snakemake benchmark file (``detect/<method>`` or the rule): its
    wall time, s, and its largest resident memory, MB (``max_rss``)."""
    out = {}
    for tsv in sorted((work / "results/benchmarks").rglob("*.tsv")):
        with tsv.open() as f:
            row = next(csv.DictReader(f, delimiter="\t"))
        rss = row.get("max_rss", "NA")
        out[str(tsv.relative_to(work / "results/benchmarks").with_suffix(""))] = (
            float(row["s"]), float(rss) if rss != "NA" else float("nan"))
    return out


def cost_table(work: Path) -> str:
    """The cost table of the workflow run in ``work``: a Markdown row per detect job,
    longest first, from the columns the job writes beside its time, and their sum."""
    from alfa_bench.workflow.job_costs import COLUMNS

    rows = []
    for tsv in sorted((work / "results/benchmarks/detect").glob("*.tsv")):
        with tsv.open() as f:
            row = next(csv.DictReader(f, delimiter="\t"))
        # NaN: a job of a commit before the costs were written
        rows.append((tsv.stem, float(row["s"]), [float(row.get(c, "nan")) for c in COLUMNS]))
    rows.sort(key=lambda r: -r[1])
    total = ("all", sum(r[1] for r in rows),
             [sum(r[2][i] for r in rows) for i in range(len(COLUMNS))])
    head = ["run", "wall s", *(c.removesuffix("_s").replace("_", " ") + (" s" if c.endswith(
        "_s") else "") for c in COLUMNS)]
    lines = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    for name, wall, values in [*rows, total]:
        cells = [f"{v:.0f}" if not c.endswith("_s") else f"{v:.2f}"
                 for c, v in zip(COLUMNS, values, strict=True)]
        lines.append(f"| {name} | {wall:.2f} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _size_mb(folder: Path) -> float:
    return sum(f.stat().st_size for f in folder.rglob("*") if f.is_file()) / 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--flights", type=int, nargs="*", default=[1, 2, 4])
    ap.add_argument("--settings", type=int, nargs="*", default=[1, 4, 16])
    ap.add_argument("--changed", action="store_true")
    ap.add_argument("--extra", type=int, default=0)
    ap.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    ap.add_argument("--methods-of", type=Path,
                    help="keep only the method runs of this checkout's config")
    ap.add_argument("--targets", nargs="+", default=["all"],
                    help="the rules to run instead of all")
    ap.add_argument("--stored", action="store_true",
                    help="run again with results/ removed but for the fits kept")
    ap.add_argument("--costs", type=Path, help="only print the cost table of this run")
    ap.add_argument("--changes", type=int, default=1,
                    help="with --changed: how many times to change the run")
    ap.add_argument("--against", type=Path,
                    help="with --changed: another checkout, run in turns with --root's")
    args = ap.parse_args()
    if args.costs:
        print(cost_table(args.costs))
        return
    root = args.root.resolve()
    processed = Path(os.environ["ALFA_DIR"]) / "processed"
    base = yaml.safe_load((root / "config/config.yaml").read_text())
    if args.methods_of:
        keep = yaml.safe_load((args.methods_of / "config/config.yaml").read_text())["methods"]
        base["methods"] = {m: s for m, s in base["methods"].items() if m in keep}
    memory, costs = {}, {}
    print("| case | flights found | method runs | wall s |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        config = tmp / "config.yaml"
        config.write_text(yaml.safe_dump(base))
        once = tmp / "alfa"
        found = replicate(processed, once / "processed", 1, args.extra)
        for k in args.flights:
            alfa = tmp / f"alfa{k}"
            n = replicate(processed, alfa / "processed", k, args.extra)
            wall, _ = run(root, alfa, config, tmp / f"flights{k}", args.targets)
            memory[f"flights x{k}"] = job_stats(tmp / f"flights{k}")
            costs[f"flights x{k}"] = cost_table(tmp / f"flights{k}")
            print(f"| flights x{k} | {n} | {len(base['methods'])} | {wall:.1f} |", flush=True)
        for k in args.settings:
            swept = dict(base)
            swept["methods"] = {**base["methods"], **{
                f"glrt_arx_pf{i}": {"detector": "glrt_residuals", "params": {
                    **base["methods"]["glrt_arx"]["params"],
                    "false_alarm": 1e-4 * (i + 1)}} for i in range(k)}}
            config = tmp / f"config{k}.yaml"
            config.write_text(yaml.safe_dump(swept))
            wall, _ = run(root, once, config, tmp / f"settings{k}", args.targets)
            print(f"| glrt_arx settings x{k} | {found} | {len(swept['methods'])} | {wall:.1f} |",
                  flush=True)
        if args.changed:
            roots = [root, *([args.against.resolve()] if args.against else [])]
            config = tmp / "changed.yaml"
            config.write_text(yaml.safe_dump(base))
            for i, r in enumerate(roots):
                wall, _ = run(r, once, config, tmp / f"changed{i}", args.targets)
                print(f"| all, before the change ({r}) | {found} | {len(base['methods'])} | "
                      f"{wall:.1f} |", flush=True)
            memory["all, from empty"] = job_stats(tmp / "changed0")
            costs["all, from empty"] = cost_table(tmp / "changed0")
            size = {}
            for f in (tmp / "changed0/results").rglob("*"):
                if f.is_file() and not f.is_symlink():
                    part = f.relative_to(tmp / "changed0/results").parts[0]
                    size[part] = size.get(part, 0) + f.stat().st_size
            sizes = f"results/ {sum(size.values()) / 1e6:.0f} MB: " + ", ".join(
                f"{p} {b / 1e6:.0f}" for p, b in sorted(size.items(), key=lambda x: -x[1]))
            changed = copy.deepcopy(base)
            for turn in range(args.changes):
                changed["methods"]["glrt_arx_chi2"]["params"]["false_alarm"] /= 2
                config.write_text(yaml.safe_dump(changed))
                order = list(enumerate(roots))[::1 - 2 * (turn % 2)]
                for i, r in order:
                    wall, jobs = run(r, once, config, tmp / f"changed{i}", args.targets)
                    ran = ", ".join(f"{rule} {k}" for rule, k in sorted(jobs.items()))
                    print(f"| all, after glrt_arx_chi2 changed, turn {turn + 1} ({r}; {ran}) "
                          f"| {found} | {len(base['methods'])} | {wall:.1f} |", flush=True)
        if args.stored:
            config = tmp / "stored.yaml"
            config.write_text(yaml.safe_dump(base))
            work = tmp / "stored"
            wall, _ = run(root, once, config, work, args.targets)
            print(f"| all, from empty | {found} | {len(base['methods'])} | {wall:.1f} |")
            costs["all, from empty"] = cost_table(work)
            for part in (work / "results").iterdir():
                if part.name != "fits":
                    shutil.rmtree(part) if part.is_dir() else part.unlink()
            stored = _size_mb(work / "results/fits")
            wall, _ = run(root, once, config, work, args.targets)
            print(f"| all, results/ removed but its fits ({stored:.0f} MB) | {found} | "
                  f"{len(base['methods'])} | {wall:.1f} |", flush=True)
            costs["all, with the fits kept"] = cost_table(work)
    if args.changed:
        print(f"\n{sizes}")
    for case, stats in memory.items():
        print(f"\nJobs of {case}: wall s, peak resident MB")
        print("\n".join(f"- {job}: {s:.2f} s, {mb:.0f} MB" for job, (s, mb) in stats.items()))
    for case, table in costs.items():
        print(f"\nCosts of {case}:\n{table}")


if __name__ == "__main__":
    main()
