"""Snakemake script: download, verify and unpack the ALFA processed flights."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

import logging
import sys

from alfa_bench.data import DownloadError, fetch_alfa
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
# the progress lines also reach the terminal: a download of a gigabyte is otherwise silent
progress = logging.StreamHandler(sys.stderr)
progress.setFormatter(logging.Formatter("download_alfa: %(message)s"))
logging.getLogger("alfa_bench.data").addHandler(progress)
d = sm.params.download
try:
    fetch_alfa(d["api"], d["file"], d["dest"], d.get("md5"), d.get("sha256"))
except DownloadError as e:
    # the details to the log; to the terminal one message, what to do, no traceback
    log = logging.getLogger("alfa_bench.data")
    log.removeHandler(progress)
    log.error("download failed: %s", e, exc_info=True)
    print(f"download_alfa: {e}", file=sys.stderr)
    sys.exit(1)
