"""What a workflow job asks a scheduler for: memory and time, scaled by the flights.

Measured in ``results/benchmarks/`` on the 6 flights of the synthetic corpus and on the
40 real flights (docs/speed.md), every job's peak memory and wall time lie under

.. math::

    m(n) = 360\\,\\mathrm{MB} + 7\\,\\mathrm{MB} \\cdot n, \\qquad
    t(n) = 5\\,\\mathrm{s} + 1.25\\,\\mathrm{s} \\cdot n

for ``n`` flights (the largest: the nested selection of a PyOD model, 600 MB and 44 s
on 40 flights). A job asks
for twice :math:`m` and three times :math:`t`, at least 5 minutes, and a retried job for
that again per attempt, so that a job SLURM stopped for memory or time gets more of it.
Beyond the measured 40 flights the lines are extrapolations.
"""

import math
from pathlib import Path

__all__ = ["ALFA_FLIGHTS", "count_flights", "job_resources"]

#: flights in ALFA's processed archive, which a download brings
ALFA_FLIGHTS = 47
MEMORY_MB = (360.0, 7.0)            # MB, MB per flight
SECONDS = (5.0, 1.25)               # s, s per flight
MEMORY_HEADROOM, TIME_HEADROOM, MIN_MINUTES = 2.0, 3.0, 5


def count_flights(processed: Path) -> int:
    """Folders under ``processed`` (the archive's count before it is downloaded).

    Every parse of the workflow counts them, each job's too, so this lists the folder
    and no more; which of them are flights the manifest decides (``find_flights`` looks
    into each)."""
    if not processed.is_dir():
        return ALFA_FLIGHTS
    return sum(p.is_dir() for p in processed.iterdir())


def job_resources(flights: int) -> dict:
    """Snakemake ``resources`` for a job over ``flights`` flights: ``mem_mb`` and
    ``runtime`` (minutes), each a function of the attempt."""
    mem_mb = math.ceil(MEMORY_HEADROOM * (MEMORY_MB[0] + MEMORY_MB[1] * flights) / 100) * 100
    minutes = max(MIN_MINUTES,
                  math.ceil(TIME_HEADROOM * (SECONDS[0] + SECONDS[1] * flights) / 60))
    return {"mem_mb": lambda wildcards, attempt: mem_mb * attempt,
            "runtime": lambda wildcards, attempt: minutes * attempt}
