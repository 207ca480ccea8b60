"""Per-rule wall time of one Snakemake run, read from its log (run without --quiet).

    python benchmarks/stages.py .snakemake/log/<run>.snakemake.log

For every rule: the jobs, the sum of their wall times, and the span from the first
job's start to the last one's end (what the rule adds to the run when its jobs run
side by side). Snakemake stamps its log to the second.
"""

from __future__ import annotations

import re
import sys
from collections import defaultdict
from datetime import datetime
from pathlib import Path

_STAMP = re.compile(r"^\[(\w{3} \w{3} +\d+ \d\d:\d\d:\d\d \d{4})\]$")
_START = re.compile(r"^(?:local)?rule (\w+):$")
_JOBID = re.compile(r"^\s+jobid: (\d+)$")
_END = re.compile(r"^Finished jobid: (\d+) \(Rule: (\w+)\)$")


def stages(log: str) -> dict[str, tuple[int, float, float]]:
    """``{rule: (jobs, summed wall s, span s)}`` from the text of a Snakemake log."""
    now = rule = None
    start, end, rules = {}, {}, {}
    for line in log.splitlines():
        if m := _STAMP.match(line):
            now = datetime.strptime(" ".join(m[1].split()), "%a %b %d %H:%M:%S %Y")
        elif m := _START.match(line):
            rule = m[1]
        elif (m := _JOBID.match(line)) and rule:
            start[m[1]], rules[m[1]], rule = now, rule, None
        elif m := _END.match(line):
            end[m[1]] = now
    jobs = defaultdict(list)
    for job, rule in rules.items():
        if job in end:
            jobs[rule].append((start[job], end[job]))
    return {rule: (len(spans), sum((b - a).total_seconds() for a, b in spans),
                   (max(b for _, b in spans) - min(a for a, _ in spans)).total_seconds())
            for rule, spans in jobs.items()}


def main() -> None:
    table = stages(Path(sys.argv[1]).read_text())
    print("| rule | jobs | wall s (sum) | span s |\n|---|---|---|---|")
    for rule, (n, total, span) in sorted(table.items(), key=lambda kv: -kv[1][2]):
        print(f"| {rule} | {n} | {total:.0f} | {span:.0f} |")


if __name__ == "__main__":
    main()
