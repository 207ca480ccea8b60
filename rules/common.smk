import os
from pathlib import Path

from snakemake.exceptions import WorkflowError

from alfa_bench.methods import make_detector

METHODS = list(config["methods"])

# the schema checks the config's shape; each method's detector and parameter names are
# checked against the registry here, before any job runs
for _name, _spec in config["methods"].items():
    try:
        make_detector(_spec["detector"], _spec.get("params"))
    except (KeyError, TypeError, ValueError) as _e:
        raise WorkflowError(f"config methods.{_name}: {_e}") from None

# ALFA_DIR, else the config's alfa_dir, else the downloaded archive.
_alfa = os.environ.get("ALFA_DIR") or config.get("alfa_dir")
DOWNLOAD = not _alfa
ALFA_DIR = Path(config["download"]["dest"] if DOWNLOAD else _alfa)
PROCESSED = ALFA_DIR / "processed"


wildcard_constraints:
    method="|".join(METHODS),
