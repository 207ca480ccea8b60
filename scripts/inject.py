"""Snakemake script: the manifest of the injected sensor-fault grid, built in memory
from the cached fault-free flights, and the flight-sensor pairs it leaves out."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

import logging

import pandas as pd

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import load_cached, read_manifest
from alfa_bench.data.inject import InjectedGrid
from alfa_bench.data.manifest import manifest_of, manifest_row
from alfa_bench.outputs.provenance import stamp
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
grid = sm.params.injection
manifest = read_manifest(sm.input.manifest)
sources = load_cached(sm.input.cache, manifest,
                      manifest.loc[manifest["fault_class"] == "none", "flight"])
flights = InjectedGrid(sources, manifest, sm.params.processed, grid["sensors"],
                       grid["faults"], grid["onsets"])
logging.info("%d injected flights; %d flight-sensor pairs skipped", len(flights),
             len(flights.skipped))
pd.DataFrame(flights.skipped, columns=["flight", "sensor", "reason"]).to_csv(
    sm.output.skipped, index=False)
stamp(sm.output.skipped, run_provenance(sm.config, manifest))
# a corpus without fault-free flights gives an empty grid: an empty manifest
manifest_of([manifest_row(flights[name], sha) for name, sha in flights.sha256.items()]
            ).to_csv(sm.output.manifest, index=False)
