"""Snakemake script: build data/flights.csv from the flights found."""

from alfa_bench.analysis.logs import log_to
from alfa_bench.data import build_manifest

log_to(snakemake.log[0])  # noqa: F821
manifest = build_manifest(snakemake.params.processed)  # noqa: F821
manifest.to_csv(snakemake.output[0], index=False)  # noqa: F821
