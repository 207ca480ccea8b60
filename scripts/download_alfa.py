"""Snakemake script: download, verify and unpack the ALFA processed flights."""

from alfa_bench.analysis.logs import log_to
from alfa_bench.data import fetch_alfa

sm = snakemake  # noqa: F821
log_to(sm.log[0])
d = sm.params.download
fetch_alfa(d["api"], d["file"], d["dest"], d.get("sha256"))
