"""Runtime of the detector jobs, from the time each writes (``results/benchmarks/detect/
<method>.tsv``, in Snakemake's benchmark columns).

One row per method run: wall and CPU seconds of its detect job (loading the flights,
building the injected ones, fitting every fold, running every flight, writing records
and traces), the real and injected flights it scored, seconds per flight scored and
peak memory. Times vary between runs, so this table
is kept apart from the results, which do not.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

__all__ = ["runtime_markdown", "runtime_table"]


def runtime_table(benchmarks: list[str | Path], flights: dict[str, int],
                  injected: dict[str, int]) -> pd.DataFrame:
    """``benchmarks``: ``results/benchmarks/detect/<method>.tsv``; ``flights`` and
    ``injected``: the number of real and injected flights each method scored."""
    rows = []
    for path in benchmarks:
        method = Path(path).stem
        b = pd.read_csv(path, sep="\t").iloc[-1]
        scored = flights.get(method, 0) + injected.get(method, 0)
        rows.append({"method": method, "flights": flights.get(method, 0),
                     "injected": injected.get(method, 0), "wall_s": b["s"],
                     "cpu_s": b["cpu_time"],
                     "s_per_flight": b["s"] / scored if scored else float("nan"),
                     "max_rss_mb": b["max_rss"]})
    return pd.DataFrame(rows)


def runtime_markdown(table: pd.DataFrame) -> str:
    lines = ["| method | flights | injected flights | wall s | CPU s | s / flight | peak MB |",
             "|---|---|---|---|---|---|---|"]
    lines += [f"| {r.method} | {r.flights} | {r.injected} | {r.wall_s:.2f} | {r.cpu_s:.2f} | "
              f"{r.s_per_flight:.3f} | {r.max_rss_mb:.0f} |" for r in table.itertuples()]
    return "\n".join(lines) + "\n"
