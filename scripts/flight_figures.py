"""Snakemake script: per flight, every method's score / threshold around the onset: the
panels each method's detect job drew, stacked under a title and over a time axis."""

from pathlib import Path

from alfa_bench.analysis import read_records
from alfa_bench.analysis.flight_figures import FlightFrame, flight_span
from alfa_bench.analysis.logs import log_to
from alfa_bench.analysis.provenance import run_provenance, stamp
from alfa_bench.data import read_manifest

sm = snakemake  # noqa: F821
log_to(sm.log[0])
manifest = read_manifest(sm.input.manifest)
flight_s = dict(zip(manifest["flight"], manifest["flight_s"], strict=True))
records = read_records(sm.input.detections)
prov = run_provenance(sm.config, manifest)
frame = FlightFrame()
for rec in {r["flight"]: r for r in records}.values():
    flight = rec["flight"]
    # a flight a method excluded has no panel of it, and is drawn without it
    strips = [p for d in sm.input.panels if (p := Path(d) / f"{flight}.png").exists()]
    path = Path(sm.output[0]) / f"{flight}.png"
    frame.draw(flight, flight_span(rec["onset_s"], float(flight_s[flight])), strips, path)
    stamp(path, prov)
