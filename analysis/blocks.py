"""The blocks runs are ranked in, and the fault classes in table order.

Honest runs (causal, sensors and setpoints only, calibrated on other dates) are ranked;
a run that reads what ALFA's fault emulation writes is marked and ranked apart;
reference rows (lateness, the emulation itself, a detector that is not causal, a
calibration that saw the scored date) come last, unranked. A run's block follows from
its detection record alone, wherever it was scored from (the workflow or
:func:`alfa_bench.evaluate`).
"""

from __future__ import annotations

from alfa_bench.data import FAULT_CLASSES

__all__ = ["BLOCKS", "BLOCK_MARKS", "FAULT_ORDER", "block"]

#: ALFA's fault classes in the tables' order (the injected sensor faults are scored apart)
FAULT_ORDER = tuple(c for c in FAULT_CLASSES if c != "sensor")

#: the blocks of runs, in the order the tables list them
BLOCKS = ("honest", "reads actuators", "reference")
#: what a section title adds to a run of each block
BLOCK_MARKS = {"honest": "", "reads actuators": " (MARKED: reads actuators)",
               "reference": " (reference)"}


def block(record: dict) -> str:
    """The block of a run, from its detection record: a reference by its role, by a
    detector that declares itself not causal (``causal``: it sees what follows the
    scored step), or by a calibration grouped by anything but the date (flights of the
    scored date then trained it), else by whether it reads a signal the fault emulation
    writes."""
    if (record.get("role") == "reference" or record.get("causal") is False
            or (record.get("calibration") or {}).get("group_by", "date") != "date"):
        return "reference"
    return "reads actuators" if record.get("reads_actuators") else "honest"
