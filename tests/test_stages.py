"""benchmarks/stages.py reads per-rule wall times out of a Snakemake log."""

import importlib.util
from pathlib import Path

spec = importlib.util.spec_from_file_location(
    "stages", Path(__file__).resolve().parent.parent / "benchmarks/stages.py")
stages = importlib.util.module_from_spec(spec)
spec.loader.exec_module(stages)

LOG = """\
[Thu Nov 26 04:48:13 2026]
localrule manifest:
    output: results/flights.csv
    jobid: 2
[Thu Nov 26 04:48:16 2026]
Finished jobid: 2 (Rule: manifest)
[Thu Nov 26 04:48:16 2026]
rule detect:
    jobid: 5
    wildcards: method=a
[Thu Nov 26 04:48:17 2026]
rule detect:
    jobid: 6
    wildcards: method=b
[Thu Nov 26 04:48:21 2026]
Finished jobid: 5 (Rule: detect)
[Thu Nov  2 04:48:25 2026]
rule never_finished:
    jobid: 9
[Thu Nov 26 04:48:27 2026]
Finished jobid: 6 (Rule: detect)
"""


def test_jobs_sums_and_spans_per_rule():
    table = stages.stages(LOG)
    assert table["manifest"] == (1, 3.0, 3.0)
    assert table["detect"] == (2, 15.0, 11.0)     # 5 s + 10 s, from 04:48:16 to 04:48:27
    assert "never_finished" not in table
