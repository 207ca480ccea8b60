import os
from pathlib import Path

METHODS = list(config["methods"])

# ALFA_DIR, else the config's alfa_dir, else the downloaded archive.
_alfa = os.environ.get("ALFA_DIR") or config.get("alfa_dir")
DOWNLOAD = not _alfa
ALFA_DIR = Path(config["download"]["dest"] if DOWNLOAD else _alfa)
PROCESSED = ALFA_DIR / "processed"


wildcard_constraints:
    method="|".join(METHODS),
