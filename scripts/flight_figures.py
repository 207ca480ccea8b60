"""Snakemake script: per flight, every method's score / threshold around the onset."""

from pathlib import Path

from alfa_bench.analysis import read_records
from alfa_bench.analysis.figures import FlightFigure
from alfa_bench.analysis.logs import log_to
from alfa_bench.analysis.provenance import run_provenance, stamp
from alfa_bench.analysis.traces import read_traces
from alfa_bench.data import read_manifest

sm = snakemake  # noqa: F821
log_to(sm.log[0])
records = read_records(sm.input.detections)
traces = read_traces(sm.input.traces, probes=False)
prov = run_provenance(sm.config, read_manifest(sm.input.manifest))
methods = list(dict.fromkeys(r["method"] for r in records))
drawers = {}    # one per set of methods: a flight a method excluded is drawn without it
for rec in {r["flight"]: r for r in records}.values():
    flight = rec["flight"]
    mine = {m: traces[m, flight] for m in methods if (m, flight) in traces}
    if tuple(mine) not in drawers:
        drawers[tuple(mine)] = FlightFigure(list(mine))
    drawers[tuple(mine)].draw(flight, rec["onset_s"], rec["fault_end_s"], mine,
                              Path(sm.output[0]) / f"{flight}.png")
    stamp(Path(sm.output[0]) / f"{flight}.png", prov)
for drawer in drawers.values():
    drawer.close()
