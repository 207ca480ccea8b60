"""`snakemake all` end to end on a synthetic corpus: outputs, contents, reproducibility."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

REPO = Path(__file__).resolve().parent.parent
SNAKEMAKE = [sys.executable, "-m", "snakemake"]


def run_workflow(workdir: Path, alfa_dir: Path) -> None:
    env = {**os.environ, "ALFA_DIR": str(alfa_dir)}
    cmd = [*SNAKEMAKE, "all", "--cores", "2", "--snakefile", str(REPO / "Snakefile"),
           "--directory", str(workdir), "--configfile", str(REPO / "config/config.yaml"),
           "--quiet"]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.fixture(scope="module")
def runs(corpus, tmp_path_factory):
    dirs = [tmp_path_factory.mktemp(f"run{i}") for i in range(2)]
    for d in dirs:
        run_workflow(d, corpus.parent)
    return dirs


def test_outputs_and_their_contents(runs, corpus):
    out = runs[0] / "results"
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    summary = pd.read_csv(out / "tables/summary.csv")
    assert set(summary["method"]) == set(config["methods"])
    assert list(summary.columns) == [
        "method", "subset", "flights", "tp", "fp", "fn", "tn", "precision", "recall",
        "accuracy", "mean_detection_s", "max_detection_s"]
    assert set(summary["subset"]) == set(config["subsets"])
    by_fault = pd.read_csv(out / "tables/by_fault.csv")
    assert {"engine", "rudder", "aileron", "none", "total"} <= set(by_fault["fault_class"])
    for method in config["methods"]:
        records = sorted((out / "detections" / method).glob("*.json"))
        assert [p.stem for p in records] == sorted(p.name for p in corpus.iterdir())
        r = json.loads(records[0].read_text())
        assert {"flight", "method", "parameters", "onset_s", "first_alarm_s", "alarm_intervals",
                "pair_first_alarm_s", "pair_armed_s", "outcome", "provenance"} <= set(r)
        assert r["provenance"]["inputs"]["flight_sha256"]
    assert "Keipour et al. ICRA 2019 (paper)" in (out / "tables/summary.md").read_text()
    comparison = pd.read_csv(out / "tables/comparison.csv")
    assert set(comparison["method"]) == set(config["methods"])
    calibrated = comparison[comparison["calibration"] != "none"]
    assert set(calibrated["detector"]) == {"glrt_residuals", "ffrls_monitor", "kalman_okid"}
    assert "Keipour et al. ICRA 2019 (paper)" in (out / "tables/comparison.md").read_text()
    assert (runs[0] / "data/flights.csv").exists()


def test_synthetic_faults_are_found(runs):
    """The synthetic faults are gross: every one is found within a second of onset."""
    summary = pd.read_csv(runs[0] / "results/tables/summary.csv").set_index(["method", "subset"])
    row = summary.loc[("rls_arx_zscore_fresh", "all")]
    assert (row["flights"], row["tp"], row["fn"]) == (6, 4, 0)
    assert row["max_detection_s"] < 1.0


def test_two_runs_are_byte_identical(runs):
    a, b = (r / "results" for r in runs)
    files = sorted(p.relative_to(a) for p in a.rglob("*")
                   if p.is_file() and "logs" not in p.parts and "benchmarks" not in p.parts)
    assert files
    for rel in files:
        assert (a / rel).read_bytes() == (b / rel).read_bytes(), rel
