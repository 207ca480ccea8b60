"""Result folders and files that no configured run writes any more: what a run taken
out of the config left behind. The workflow names them at the start of a run and
``snakemake remove_stale`` removes them, so that nothing reads a run that is gone."""

from __future__ import annotations

import shutil
from pathlib import Path

__all__ = ["PER_RUN", "RETIRED", "remove", "stale_results"]

#: where each run writes, ``{run}`` its name
PER_RUN = ("detections/{run}", "traces/{run}", "figure_parts/{run}",
           "injected/detections/{run}", "benchmarks/detect/{run}.tsv", "logs/detect/{run}.log")
#: what earlier versions of the workflow wrote and this one does not: each run's part of
#: the recordings (``rerun_logs`` writes them from the traces now)
RETIRED = ("rerun_parts",)


def stale_results(results: str | Path, runs) -> list[Path]:
    """The per-run folders and files under ``results`` of a run not among ``runs``,
    and the :data:`RETIRED` folders."""
    results, runs = Path(results), set(runs)
    out = [results / r for r in RETIRED if (results / r).exists()]
    for pattern in PER_RUN:
        parent, name = (results / pattern).parent, Path(pattern).name
        suffix = name.removeprefix("{run}")
        if parent.is_dir():
            out += [p for p in sorted(parent.iterdir())
                    if p.name.endswith(suffix) and p.name.removesuffix(suffix) not in runs
                    and (p.is_dir() if not suffix else p.is_file())]
    return out


def remove(paths) -> None:
    """Remove each folder or file of ``paths``."""
    for path in map(Path, paths):
        shutil.rmtree(path) if path.is_dir() else path.unlink()
