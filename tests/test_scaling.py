"""benchmarks/scaling.py lays measured job times out along the rule graph, and the
resources each rule declares (workflow/resources.py) hold what its jobs use."""

import csv
import importlib.util
from pathlib import Path

import pytest

from alfa_bench.workflow.resources import count_flights, job_resources

spec = importlib.util.spec_from_file_location(
    "scaling", Path(__file__).resolve().parent.parent / "benchmarks/scaling.py")
scaling = importlib.util.module_from_spec(spec)
spec.loader.exec_module(scaling)

#: manifest, then three detect jobs side by side, then tables; `all` waits for tables
SECONDS = {"manifest": [2.0], "detect": [4.0, 6.0, 10.0], "tables": [3.0]}
AFTER = {"manifest": set(), "detect": {"manifest"}, "tables": {"detect"},
         "all": {"tables"}}


def test_two_cores_take_half_the_work_or_the_critical_path():
    local, _ = scaling.estimate(SECONDS, AFTER, 1.0, 0.0, nodes=50)
    assert local == max(25.0 / 2, 2.0 + 10.0 + 3.0)
    local, _ = scaling.estimate({**SECONDS, "detect": [10.0] * 6}, AFTER, 1.0, 0.0, 50)
    assert local == 65.0 / 2


def test_nodes_run_the_critical_path_with_each_jobs_start_up_in_waves():
    _, cluster = scaling.estimate(SECONDS, AFTER, 2.0, 5.0, nodes=50)
    assert cluster == (4 + 5) + (20 + 5) + (6 + 5)
    _, two_nodes = scaling.estimate(SECONDS, AFTER, 1.0, 0.0, nodes=2)
    assert two_nodes == 2.0 + 2 * 10.0 + 3.0          # three detect jobs, two at a time


def test_job_resources_grow_with_the_flights_and_the_attempt(tmp_path):
    for n in range(3):
        (tmp_path / f"flight{n}").mkdir()
    (tmp_path / "README.md").write_text("not a flight")
    assert count_flights(tmp_path) == 3
    assert count_flights(tmp_path / "not yet downloaded") == 47
    small, large = job_resources(40), job_resources(4700)
    assert small["mem_mb"](None, 1) == 1300 and small["runtime"](None, 1) == 5
    assert large["mem_mb"](None, 1) == 66_600 and large["runtime"](None, 1) == 294
    assert small["mem_mb"](None, 2) == 2 * small["mem_mb"](None, 1)
    assert large["runtime"](None, 3) == 3 * large["runtime"](None, 1)


@pytest.mark.workflow
def test_every_job_of_a_run_used_less_than_its_rule_declared(runs, corpus):
    """The synthetic run's jobs, measured by Snakemake's benchmark, against what their
    rules ask a scheduler for: a job over its memory or time would be killed."""
    declared = job_resources(count_flights(corpus))
    mem_mb, minutes = declared["mem_mb"](None, 1), declared["runtime"](None, 1)
    tsvs = sorted((runs[0] / "results/benchmarks").rglob("*.tsv"))
    assert len(tsvs) >= 30
    for tsv in tsvs:
        with open(tsv) as f:
            row = next(csv.DictReader(f, delimiter="\t"))
        assert float(row["s"]) < 60 * minutes, tsv.name
        assert float(row["max_rss"]) < mem_mb, tsv.name
