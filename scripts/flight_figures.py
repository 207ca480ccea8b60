"""Snakemake script: per flight, every method's score / threshold around the onset: the
panels each method's detect job drew, stacked under a title and over a time axis."""

from alfa_bench.workflow.script_job import forked

# in a fork of the workflow's script server, its imports made, when one answers
forked(snakemake, __file__)  # noqa: F821

from pathlib import Path

from alfa_bench.analysis.provenance import run_provenance
from alfa_bench.data import read_manifest
from alfa_bench.outputs.flight_figures import FlightFrame, flight_span
from alfa_bench.outputs.provenance import stamp
from alfa_bench.outputs.records import iter_records
from alfa_bench.workflow.logs import log_to

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
flight_s = dict(zip(manifest["flight"], manifest["flight_s"], strict=True))
# each flight any method scored, and its onset: the records, read one at a time
onsets = {r["flight"]: r["onset_s"] for r in iter_records(sm.input.detections)}
prov = run_provenance(sm.config, manifest)
frame = FlightFrame()
for flight, onset_s in onsets.items():
    # a flight a method excluded has no panel of it, and is drawn without it
    strips = [p for d in sm.input.panels if (p := Path(d) / f"{flight}.png").exists()]
    path = Path(sm.output[0]) / f"{flight}.png"
    frame.draw(flight, flight_span(onset_s, float(flight_s[flight])), strips, path)
    stamp(path, prov)
