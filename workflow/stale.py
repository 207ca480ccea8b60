"""Result folders and files that no configured run writes any more: what a run taken
out of the config left behind. The workflow names them at the start of a run and
``snakemake remove_stale`` removes them, so that nothing reads a run that is gone."""

from __future__ import annotations

import shutil
from pathlib import Path

__all__ = ["PER_RUN", "RETIRED", "remove", "stale_results"]

#: where each run writes, ``{run}`` its name
PER_RUN = ("detections/{run}", "traces/{run}", "figure_parts/{run}",
           "injected/detections/{run}", "benchmarks/detect/{run}.tsv", "logs/detect/{run}.log",
           "rerun/{run}", "benchmarks/run_parts/{run}.tsv", "logs/run_parts/{run}.log",
           *(f"parts/{table}/{{run}}.csv" for table in ("sweep", "detectability",
                                                         "isolation_sensors",
                                                         "isolation_actuators")),
           *(f"parts/{table}/{{run}}.jsonl" for table in ("per_flight", "records")))
#: what earlier versions of the workflow wrote and this one does not, as globs: each
#: run's part of the recordings kept beside them, and the recordings written whole
#: (each flight's are in parts now, under ``rerun/<part>/``)
RETIRED = ("rerun_parts", "rerun/*.rrd")


def stale_results(results: str | Path, runs) -> list[Path]:
    """The per-run folders and files under ``results`` of a run not among ``runs``,
    and the :data:`RETIRED` folders."""
    results, runs = Path(results), set(runs)
    out = [p for r in RETIRED for p in sorted(results.glob(r))]
    for pattern in PER_RUN:
        parent, name = (results / pattern).parent, Path(pattern).name
        suffix = name.removeprefix("{run}")
        if parent.is_dir():
            out += [p for p in sorted(parent.iterdir())
                    if p.name.endswith(suffix) and p.name.removesuffix(suffix) not in runs
                    # a run's name starts with a letter (the config's schema): not a
                    # part every run shares (``rerun/_flight``)
                    and not p.name.startswith("_")
                    and (p.is_dir() if not suffix else p.is_file())]
    return out


def remove(paths) -> None:
    """Remove each folder or file of ``paths``."""
    for path in map(Path, paths):
        shutil.rmtree(path) if path.is_dir() else path.unlink()
