"""The README's first command on a corpus of logs none of us recorded: PX4's own ULogs
(../shared/logs/px4, fault-free multicopter flights) with a labels.csv and one broken
log, through the workflow with `--config corpus=...` to its tables and page."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pandas as pd
import pytest
from unavailable import require_module, unavailable
from workflow_runs import REPO, run_workflow

# the workflow in a subprocess, to the tables and the page
pytestmark = pytest.mark.workflow

PX4 = Path(__file__).resolve().parents[2] / "shared" / "logs" / "px4"


@pytest.fixture(scope="module")
def ulog_run(tmp_path_factory):
    require_module("pyulog")
    # three of the five: enough for folds, a run ranked and the gaps between logs
    logs = [PX4 / n for n in ("sample.ulg", "sample_logging_tagged_and_default_params.ulg",
                              "sample_px4_events.ulg")]
    if not all(p.is_file() for p in logs):
        unavailable(f"PX4's sample ULogs are not at {PX4}")
    root = tmp_path_factory.mktemp("own")
    corpus = root / "logs"
    corpus.mkdir()
    for log in logs:
        shutil.copy(log, corpus / log.name)
    (corpus / "cut.ulg").write_bytes(logs[0].read_bytes()[:3000])
    names = [p.name for p in logs]
    pd.DataFrame({"log": [*names, "cut.ulg"], "fault": "", "onset_s": "",
                  "group": [f"g{i}" for i in range(len(names))] + ["g0"]}
                 ).to_csv(corpus / "labels.csv", index=False)
    work = root / "run"
    work.mkdir()
    # the tables and the page: what this file checks (the paper, recordings and figures
    # are the ALFA runs' tests')
    done = run_workflow(work, None, "--config", f"corpus={corpus}",
                        target=["results/index.html", "results/tables/comparison.md"])
    return work / "results", done


def test_a_ulog_corpus_runs_through_with_a_run_ranked(ulog_run):
    results, done = ulog_run
    comparison = pd.read_csv(results / "tables/comparison.csv")
    primary = comparison[comparison["subset"] == comparison["subset"].iloc[0]]
    assert primary["rank"].notna().sum() >= 1
    # fault-free flights only: no recall, and the tables and page say so
    assert (primary["tp"] + primary["fn"]).max() == 0
    assert "recall cannot be computed" in (results / "tables/comparison.md").read_text()
    assert "recall cannot be computed" in (results / "index.html").read_text()
    assert "the logs of" in (results / "index.html").read_text()


def test_runs_needing_signals_a_multicopter_lacks_are_named(ulog_run):
    results, _ = ulog_run
    na = pd.read_csv(results / "tables/not_applicable.csv")
    assert "okid_bank" in set(na["method"])
    why = na.set_index("method").at["okid_bank", "missing"]
    assert why.startswith("airspeed_cmd (the log holds no tecs_status")
    md = (results / "tables/comparison.md").read_text()
    assert "### Runs not applicable to this corpus" in md and "`okid_bank`: reads" in md
    assert "Not applicable to this corpus" in (results / "index.html").read_text()
    ranked = set(pd.read_csv(results / "tables/comparison.csv")["method"])
    assert not ranked & set(na["method"])


def test_a_broken_log_is_left_out_and_named_not_a_stopped_run(ulog_run):
    results, _ = ulog_run
    left = pd.read_csv(results / "corpus/left_out.csv")
    assert list(left["log"]) == ["cut.ulg"] and left["line"].tolist() == [5]
    failures = pd.read_csv(results / "load_failures.csv")
    assert "cut.ulg" in set(failures["flight"])
    assert len(pd.read_csv(results / "flights.csv")) == 3


def test_the_corpus_files_read_with_their_documented_header(ulog_run):
    results, _ = ulog_run
    documented = dict(re.findall(r"^- `(results/corpus/[^`]+\.csv)`: (.+)$",
                                 (REPO / "docs/outputs.md").read_text(), flags=re.M))
    assert {f"results/corpus/{p.name}" for p in (results / "corpus").glob("*.csv")} == set(
        documented)
    for name, header in documented.items():
        frame = pd.read_csv(results.parent / name)
        assert list(frame.columns) == re.findall(r"`([^`]+)`", header), name
    converted = sorted((results / "corpus/processed").iterdir())
    assert len(converted) == 3 and all(p.name.startswith("log_g") for p in converted)
