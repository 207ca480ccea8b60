"""`snakemake all` end to end on a synthetic corpus: outputs, contents, reproducibility."""

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from broken import (
    GT,
    IMU,
    ROLL,
    _gap,
    _late_start,
    edit,
    set_cell,
    shift_time,
    topic_file,
)
from unavailable import unavailable
from workflow_runs import (
    GRID,
    REPO,
    SNAKEMAKE,
    assert_same_results,
    dry_run_with_changed,
    run_workflow,
)

from alfa_bench.data.synthetic import write_flight
from alfa_bench.methods import REGISTRY
from alfa_bench.outputs.figures import DPI, SWEEP_SIZE
from alfa_bench.outputs.provenance import RUN_FILE, read_provenance, read_table
from alfa_bench.outputs.records import INJECTED_RECORDS, RUN_RECORD, iter_records, read_run_record
from alfa_bench.outputs.traces import read_trace

YAW, WIND, ERRORS = ("mavros-nav_info-yaw", "mavros-wind_estimation",
                     "mavros-nav_info-errors")

# Snakemake or pip in a subprocess, minutes in all: `pytest -m "not workflow"` skips them
pytestmark = pytest.mark.workflow


def test_outputs_and_their_contents(runs, corpus):
    out = runs[0] / "results"
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    summary = read_table(out / "tables/summary.csv")
    assert set(summary["method"]) == set(config["methods"])
    scores = ["tp", "fp", "fn", "tn", "precision", "recall", "accuracy", "mean_detection_s",
              "max_detection_s"]
    assert list(summary.columns[:5]) == ["method", "subset", "block", "deadline_s", "flights"]
    assert {*scores, *(f"{c}_paper" for c in scores), "precision_low", "accuracy_high",
            "excluded"} <= set(summary.columns)
    assert (summary["deadline_s"] == config["scoring"]["deadline_s"]).all()
    assert (summary["excluded"] == 0).all()
    assert read_table(out / "tables/failures.csv").empty
    assert set(summary["subset"]) == set(config["subsets"])
    by_fault = read_table(out / "tables/by_fault.csv")
    assert {"engine", "rudder", "aileron", "none", "total"} <= set(by_fault["fault_class"])
    for method in config["methods"]:
        records = sorted((out / "detections" / method).glob("*.json"))
        assert [p.stem for p in records] == sorted(p.name for p in corpus.iterdir())
        r = json.loads(records[0].read_text())
        assert {"flight", "method", "parameters", "onset_s", "first_alarm_s", "alarm_intervals",
                "pair_first_alarm_s", "pair_armed_s", "outcome", "provenance", "role",
                "reads_actuators", "signal_kinds", "skipped_channels",
                "isolated_sensor"} <= set(r)
        assert r["provenance"]["inputs"]["flight_sha256"]
    # the traces keep the intermediates the rerun recordings show
    assert read_trace(next((out / "traces/rls_arx_zscore").glob("*.npz"))).probes
    assert "Keipour et al. ICRA 2019 (paper)" in (out / "tables/summary.md").read_text()
    comparison = read_table(out / "tables/comparison.csv")
    assert set(comparison["method"]) == set(config["methods"])
    calibrated = comparison[comparison["calibration"] != "none"]
    assert set(calibrated["detector"]) == {
        spec["detector"] for spec in config["methods"].values()
        if REGISTRY[spec["detector"]].calibrated}
    assert "Keipour et al. ICRA 2019 (paper)" in (out / "tables/comparison.md").read_text()
    block = dict(zip(comparison["method"], comparison["block"], strict=False))
    assert block["end_of_flight"] == block["emulation_oracle"] == "reference"
    assert block["ffrls_monitor_servo"] == block["okid_bank_servo"] == "reads actuators"
    assert block["ffrls_monitor"] == block["rls_arx_zscore"] == "honest"
    for subset, table in comparison.groupby("subset"):   # only honest methods are ranked
        ranked = table.dropna(subset=["rank"])
        assert set(ranked["block"]) == {"honest"}, subset
        assert sorted(ranked["rank"]) == list(range(1, len(ranked) + 1))
        assert list(table["block"]) == sorted(table["block"], key=["honest", "reads actuators",
                                                                   "reference"].index)
    assert (runs[0] / "results/flights.csv").exists()


def test_inspection_outputs_sweeps_figures_and_paper(runs, corpus):
    work = runs[0]
    out = work / "results"
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    flights = sorted(p.name for p in corpus.iterdir())
    # each flight's recording in parts: its own, and each run's
    assert sorted(p.stem for p in (out / "rerun/_flight").glob("*.rrd")) == flights
    for method in config["methods"]:
        assert sorted(p.stem for p in (out / "traces" / method).glob("*.npz")) == flights
        assert sorted(p.stem for p in (out / "rerun" / method).glob("*.rrd")) == flights
    sweep = read_table(out / "tables/sweep.csv")
    assert set(sweep["method"]) == set(config["methods"])
    assert (sweep["scale"] == 1.0).any()
    summary = read_table(out / "tables/summary.csv").set_index(["method", "subset"])
    at_one = sweep[sweep["scale"] == 1.0].set_index(["method", "subset"])
    for col in ("tp", "fp", "fn", "tn"):  # the sweep at scale 1 is the configured run
        assert (at_one[col] == summary.loc[at_one.index, col]).all(), col
    for png in ("sweep.png", "detection_time.png"):
        assert (out / "figures" / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.stem for p in (out / "figures/flights").glob("*.png")) == flights
    for table in ("summary", "by_fault", "comparison"):
        assert "\\toprule" in (out / "tables" / f"{table}.tex").read_text()
    paper = (work / "paper/build/paper.md").read_text()
    assert "{{" not in paper and "| method | detector |" in paper
    assert r"\csname abresult@flights:all\endcsname{6}" in (
        work / "paper/build/results.tex").read_text()


def test_the_injected_grid_is_scored_and_isolated(runs, corpus):
    """The grid over the corpus's fault-free flights, every method scored on it, its
    detectability and both isolation matrices."""
    out = runs[0] / "results"
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    grid = GRID
    sources = [p for p in corpus.iterdir() if p.name.endswith("no_failure")]
    sensors = grid["sensors"]
    injected = read_table(out / "injected/flights.csv")
    assert len(injected) == len(sources) * len(sensors) * len(grid["faults"]) * len(
        grid["onsets"])
    assert set(injected["fault_sensor"]) == set(sensors)
    assert set(injected["fault_class"]) == {"sensor"}
    detectors = [m for m, spec in config["methods"].items() if spec.get("role") != "reference"]
    table = read_table(out / "tables/detectability.csv")
    assert set(table["method"]) == set(detectors)
    assert (table.groupby("method")["flights"].sum() == len(injected)).all()
    assert ((table["detected"] + table["alarmed_before_onset"] + table["missed"])
            == table["flights"]).all()
    assert table["chance_rate"].between(0, 1).all()
    sensors_iso = read_table(out / "tables/isolation_sensors.csv")
    assert len(sensors_iso) == len(injected) * len(detectors)
    assert read_table(out / "injected/skipped.csv").empty   # every sensor is live here
    # an injected record names its fold and its flight's checksum; the folder's run
    # record holds, once, the fold's calibration as the source's own record has it
    folder = out / "injected/detections/glrt_arx"
    run = read_run_record(folder)
    records = list(iter_records([folder]))
    assert len(records) == len(injected)
    assert [r["flight"] for r in records] == sorted(injected["flight"])
    # one JSON object a line, as pandas and DuckDB read it by default
    import duckdb
    import pandas as pd
    lines = folder / INJECTED_RECORDS
    assert pd.read_json(lines, lines=True)["flight"].tolist() == sorted(injected["flight"])
    assert len(duckdb.sql(f"select flight from read_json('{lines}')").fetchall()) == len(records)
    sha = dict(zip(injected["flight"], injected["sha256"], strict=True))
    real = {r["flight"]: r for r in iter_records([out / "detections/glrt_arx"])}
    source = dict(zip(injected["flight"], injected["fault_source"], strict=True))
    for r in records:
        assert r["provenance"] == {"flight_sha256": sha[r["flight"]], "run": RUN_RECORD}
        assert run["folds"][r["calibration"]["fold"]] == real[source[r["flight"]]]["calibration"]
    assert set(run["provenance"]) == {"code", "packages", "config", "calibration"}
    actuators = read_table(out / "tables/isolation_actuators.csv")
    assert set(actuators["true"]) == {"engine", "rudder", "aileron"}
    assert "true \\ isolated" in (out / "tables/isolation_actuators.md").read_text()
    assert (out / "figures/detectability.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_html_report_holds_the_figures_and_tables(runs, corpus):
    work = runs[0]
    cmd = [*SNAKEMAKE, "--report", str(work / "report.html"), "--snakefile",
           str(REPO / "Snakefile"), "--directory", str(work), "--configfile",
           str(REPO / "config/config.yaml")]
    done = subprocess.run(cmd, env={**os.environ, "ALFA_DIR": str(corpus.parent)},
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    html = (work / "report.html").read_text()
    for name in ("sweep.png", "detection_time.png", "comparison.csv", "paper.md"):
        assert name in html, name
    # in a real browser: it opens on the overview, the headline table and the figures show
    from alfa_bench.workflow.report_page import open_report
    from alfa_bench.workflow.viewer import chromium
    if chromium() is None:
        unavailable("no Chromium (apt-get install chromium): the report was not opened")
    view = open_report(work / "report.html", work / "report.png", "Comparison",
                       "results/tables/comparison.html")
    assert "Start here." in view.overview and not view.errors
    assert any("Headline: subset `no_emr`".replace("`", "") in f for f in view.frames)
    view = open_report(work / "report.html", work / "report.png", "Detection times",
                       "results/figures/detection_time.png")
    assert view.images and min(view.images) > 100, view


def test_the_results_page_opens_on_the_headline(runs):
    """results/index.html, in a 1400 x 900 window without a click or a scroll: the best
    honest run's row with its numbers, the per-class table, and a figure that loads; no
    page wider than the window, no external asset."""
    page = runs[0] / "results/index.html"
    text = page.read_text()
    assert "http://" not in text and "https://" not in text
    from alfa_bench.workflow.report_page import open_index
    from alfa_bench.workflow.viewer import chromium
    if chromium() is None:
        unavailable("no Chromium (apt-get install chromium): the page was not opened")
    view = open_index(page, runs[0] / "index.png")
    comparison = read_table(runs[0] / "results/tables/comparison.csv")
    best = comparison[(comparison["subset"] == "no_emr") & (comparison["rank"] == 1)].iloc[0]
    headline, by_class = view.first_rows[:2]
    assert headline.split("\t")[:4] == [
        "1", best["method"], best["family"], f"{best['tp']} of {best['tp'] + best['fn']}"], view
    assert by_class.split("\t")[:2] == ["1", best["method"]], view
    assert view.images and min(view.images) > 100 and not view.errors, view
    assert view.images_in_view == len(view.images) and view.page_width <= 1400, view
    # the figure is drawn for its column: shown at its own width, its text as drawn
    assert view.images == [round(SWEEP_SIZE[0] * DPI)], view


def test_the_results_page_says_who_is_really_ahead_and_every_link_resolves(runs):
    """The tie with the leader in plain words at the top, every unranked run listed with
    why, and every link and image of the page a file the run wrote."""
    out = runs[0] / "results"
    text = (out / "index.html").read_text()
    comparison = read_table(out / "tables/comparison.csv")
    rows = comparison[comparison["subset"] == "no_emr"]
    ranked = rows[rows["rank"].notna()]
    same = int(((ranked["rank"] > 1) & (ranked["vs_best_p"] >= 0.05)).sum())
    lead = text.split('<p class="lead">')[1].split("</p>")[0]
    assert (f"cannot tell the leader, <code>{ranked.sort_values('rank')['method'].iloc[0]}"
            in lead) and f"apart from {same} of the other {len(ranked) - 1} ranked" in lead
    unranked = text.split("<h2>Not ranked")[1]
    for r in rows[rows["rank"].isna()].to_dict(orient="records"):
        assert f"<li><code>{r['method']}</code>: " in unranked, r["method"]
    links = re.findall(r'(?:href|src)="([^"]+)"', text)
    assert {"tables/comparison.html", "tables/ceiling.md"} <= set(links)
    missing = [u for u in links if not u.startswith("data:")
               and not (out / u.split("#")[0]).is_file()]
    assert not missing, missing


def test_the_honest_benchmark_outputs(runs):
    """The leakage audit, the deadline curve and the reference rows, on the corpus."""
    out = runs[0] / "results"
    leak = read_table(out / "tables/leakage.csv")
    leaking = set(map(tuple, leak.loc[leak["leaks"], ["signal", "fault_class"]].to_numpy()))
    assert {("servo_throttle", "engine"), ("throttle", "engine"),
            ("servo_rudder", "rudder")} <= leaking
    assert not set(leak.loc[leak["leaks"], "kind"]) - {"actuator"}
    assert "Which signals carry the label" in (out / "tables/leakage.md").read_text()
    # the headline first, under the audit's verdict on it
    comparison = (out / "tables/comparison.md").read_text()
    assert comparison.startswith("The headline subset `no_emr`")
    assert "finds no sensor or setpoint carrying the label" in comparison.splitlines()[0]
    assert "### Headline: subset `no_emr`" in comparison
    deadline = read_table(out / "tables/deadline.csv")
    for _, g in deadline.groupby(["method", "subset"]):
        assert g.sort_values("deadline_s")["detected"].is_monotonic_increasing
    assert (out / "figures/deadline.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    summary = read_table(out / "tables/summary.csv").set_index(["method", "subset"])
    end = summary.loc[("end_of_flight", "all")]
    # lateness alone: every fault flight "detected" by the paper's rule, none in time
    assert (end["tp"], end["tp_paper"], end["fn_paper"]) == (0, 4, 0)
    oracle = summary.loc[("emulation_oracle", "all")]
    assert oracle["tp"] >= 2      # the engine flights: throttle flat at onset


def test_synthetic_faults_are_found(runs):
    """The synthetic faults are gross: every one is found within a second of onset."""
    summary = read_table(runs[0] / "results/tables/summary.csv").set_index(["method", "subset"])
    row = summary.loc[("rls_arx_zscore_fresh", "all")]
    assert (row["flights"], row["tp"], row["fn"]) == (6, 4, 0)
    assert row["max_detection_s"] < 1.0


def test_every_result_file_records_its_provenance(runs, corpus):
    work = runs[0]
    # data, not results: the injected flights' manifest lists checksums, and the
    # parsed-flight cache is keyed by them
    files = [p for p in (work / "results").rglob("*") if p.is_file()
             and not p.name.startswith(".snakemake")     # Snakemake's directory markers
             # the fits the jobs share (model files, no result), and each run's parts
             # of the tables (its rows, whose table records the provenance)
             and not {"logs", "benchmarks", "cache", "rerun_parts", "figure_parts", "fits",
                      "parts"}
             & set(p.relative_to(work).parts)
             and p not in (work / "results/injected/flights.csv", work / RUN_FILE)
             and p.name != RUN_RECORD]     # what the injected records share: read through them
    files += [work / "paper/build/paper.md", work / "paper/build/results.tex"]
    assert {p.suffix for p in files} == {".csv", ".md", ".tex", ".json", ".jsonl", ".npz", ".png",
                                         ".rrd", ".parquet", ".html"}
    flights = {p.name for p in corpus.iterdir()}
    injected = set(read_table(work / "results/injected/flights.csv")["flight"])
    for path in files:
        prov = read_provenance(path)
        assert prov["code"]["version"] and "git_commit" in prov["code"], path
        assert prov["packages"]["numpy"] and prov["config"], path
        inputs = prov["inputs"]
        if path.suffix in (".json", ".npz") or (
                path.suffix == ".rrd" and path.parent.name != "_flight"):
            # one flight's run, and its calibration (a run's part of a recording: its trace's)
            assert len(inputs["flight_sha256"]) == 64, path
            checksums = inputs["calibration_sha256"]
        elif path.suffix == ".rrd":          # a flight's own part of its recording
            assert len(inputs["flight_sha256"]) == 64, path
            assert set(prov["config"]) == {"runs", "signals"}, path
            continue
        elif path.suffix == ".jsonl":       # every injected flight's run, and the folds'
            checksums = inputs["flight_sha256"]
            assert set(checksums) == injected, path
            assert flights >= set(inputs["calibration_sha256"]), path
        else:                                    # every flight, and the calibration folds
            checksums = inputs["flight_sha256"]
            assert flights <= set(checksums), path
            assert set(prov["calibration"]["training_flights"]) == {
                "2018-07-18", "2018-07-30", "2018-09-11", "2018-10-05"}, path
        assert all(len(v) == 64 for v in checksums.values()), path


def test_a_changed_method_module_reruns_exactly_its_jobs(runs, overlay):
    """A changed detector module makes a dry run schedule the detect jobs (real flights
    and injected grid) of the runs whose detectors use it (here residual_bank, its
    energy variant, its nested selection, learned_fusion and the project's classifier
    on top of it), and their parts jobs, and no other
    method's: not the coincidence runs, which share its windows and thresholds
    (methods/windows.py, methods/extremes.py) but not its module. (Snakemake compares small
    inputs by content, so the module's text changes, by one comment line, and is
    restored byte for byte.)"""
    done = dry_run_with_changed(REPO / "methods/residual_bank.py", runs[1], overlay,
                                "test_workflow")
    jobs = re.findall(r"rule (\w+):\n(?:    .*\n)*?    wildcards: method=(\w+)", done.stdout)
    using = ("bench_logistic", "bench_logistic_no_emr", "learned_fusion", "residual_bank",
             "residual_bank_energy", "residual_bank_nested")
    assert sorted(jobs) == sorted((rule, m) for rule in ("detect", "run_parts")
                                  for m in using), done.stdout + done.stderr


def _expand(path: str) -> list[str]:
    """``a/{b,c}.d`` -> ``[a/b.d, a/c.d]``; ``<name>`` placeholders become ``*``."""
    path = re.sub(r"<[^>]+>", "*", path)
    m = re.search(r"\{([^}]*)\}", path)
    if not m:
        return [path]
    return [q for alt in m.group(1).split(",")
            for q in _expand(path[:m.start()] + alt + path[m.end():])]


def test_every_results_path_the_docs_name_is_made_by_the_workflow(runs):
    """A results file the README, docs or paper point a reader to must exist after
    `snakemake all`, or the pointer is stale."""
    texts = [REPO / "README.md", REPO / "paper/paper.template.md",
             *sorted((REPO / "docs").glob("*.md"))]
    named = {p for f in texts for p in re.findall(r"`(results/[^`]*)`", f.read_text())}
    assert len(named) > 10
    named -= {"results/injected/processed/",         # `snakemake injected_csv` writes it
              "results/tables/stability_refit.{csv,md}"}   # `snakemake stability_refit`
    # written on a corpus of logs only (tests/test_own_flights.py)
    named = {p for p in named if not p.startswith("results/corpus/")}
    missing = [p for p in sorted(named) for q in _expand(p)
               if not list(runs[0].glob(q.rstrip("/")))]
    assert not missing, missing


def test_the_tables_merged_from_each_runs_part_are_those_of_every_run_at_once(runs):
    """sweep, per_flight, the records, detectability and isolation are merged from
    each run's part (rules/parts.smk): each equals, byte for byte (Parquet: its
    table), the table computed from every run's records and traces in one go."""
    import io

    import pandas as pd

    from alfa_bench.analysis.detectability import detectability_table
    from alfa_bench.analysis.isolation import isolation_rows
    from alfa_bench.analysis.per_flight import per_flight_table
    from alfa_bench.analysis.sweep import sweep_table
    from alfa_bench.data import read_manifest
    from alfa_bench.outputs.parquet import records_table
    from alfa_bench.outputs.records import read_records
    from alfa_bench.outputs.traces import read_traces

    out = runs[0] / "results"
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    methods = list(config["methods"])
    detectors = [m for m in methods if config["methods"][m].get("role") != "reference"]
    primary = config["primary_subset"]
    subsets = [primary, *(s for s in config["subsets"] if s != primary)]
    deadline = config["scoring"]["deadline_s"]
    manifest, injected = (read_manifest(out / "flights.csv"),
                          read_manifest(out / "injected/flights.csv"))
    records = read_records([out / "detections" / m for m in methods])
    traces = read_traces([out / "traces" / m for m in methods], probes=False)
    on_grid = [out / "injected/detections" / m for m in detectors]
    clean = [r for r in records if r["method"] in detectors]

    def csv(table):
        return table.to_csv(index=False).encode()

    whole = {
        "sweep": csv(sweep_table(records, traces, manifest, subsets, deadline)),
        "per_flight": csv(per_flight_table(records, traces, manifest, deadline)),
        "detectability": csv(detectability_table(iter_records(on_grid), injected, clean)),
        "isolation_sensors": csv(isolation_rows(iter_records(on_grid), "sensor")),
        "isolation_actuators": csv(isolation_rows(clean, "actuator")),
    }
    assert len(pd.read_csv(io.BytesIO(whole["detectability"]))) > 0
    for table, expected in whole.items():
        assert (out / f"tables/{table}.csv").read_bytes() == expected, table
    merged = pd.read_parquet(out / "tables/detections.parquet")
    pd.testing.assert_frame_equal(merged, records_table(records))


def test_two_runs_are_byte_identical(runs):
    """Every result is byte-identical between runs (the recordings' content is)."""
    assert assert_same_results(*runs) > 50


@pytest.fixture(scope="module")
def broken_corpus(corpus, tmp_path_factory):
    """The corpus plus a flight that cannot be read at all and one with a 5 s gap in
    its IMU topic."""
    root = tmp_path_factory.mktemp("broken")
    shutil.copytree(corpus, root / "processed")
    unreadable = write_flight(root / "processed", "carbonZ_2018-09-11-14-22-07_2_no_failure",
                              seed=7)
    (unreadable / f"{unreadable.name}-{ROLL}.csv").write_text("")
    gap = write_flight(root / "processed", "carbonZ_2018-10-05-15-55-10_elevator_failure",
                       onset_s=40.0, fault_topic="failure_status-elevator", seed=8)
    edit(IMU, _gap)(gap)
    return root, unreadable.name, gap.name


def test_strict_mode_stops_at_the_first_broken_flight(broken_corpus, tmp_path):
    root, unreadable, _ = broken_corpus
    done = run_workflow(tmp_path, root, "--config", "strict=True",
                        target="results/tables/summary.csv", ok=False)
    log = (tmp_path / "results/logs/manifest.log").read_text()
    assert f"flight {unreadable}" in log and "empty file" in log, done.stderr


def _small_corpus(root: Path, specs: dict) -> Path:
    for name, kw in specs.items():
        write_flight(root / "processed", name, **kw)
    return root


@pytest.mark.parametrize("specs, why", [
    # only faulty flights: nothing to inject sensor faults into, and too little
    # fault-free data before the onsets for a per-sample P_F (a single date, the other
    # small set, is a failure row for every flight: tests/test_calibration.py)
    ({"carbonZ_2018-07-18-15-53-31_1_engine_failure": dict(onset_s=50.0),
      "carbonZ_2018-07-30-16-29-45_engine_failure_with_emr_traj": dict(onset_s=55.0, seed=2),
      "carbonZ_2018-09-11-15-06-34_3_rudder_left_failure":
          dict(onset_s=45.0, fault_topic="failure_status-rudder", code=2, seed=3)},
     "cannot resolve P_F"),
], ids=["faulty-only"])
def test_small_and_one_sided_flight_sets_run_to_the_end(specs, why, tmp_path):
    """A method that cannot be calibrated on such a set ends its own run on those flights
    (failures.csv, stage calibration, with what to change), and every other method is
    scored."""
    root = _small_corpus(tmp_path / "alfa", specs)
    work = tmp_path / "work"
    grid = tmp_path / "grid.yaml"
    grid.write_text(yaml.safe_dump({"injection": GRID}))
    run_workflow(work, root, "--configfile", str(REPO / "config/config.yaml"), str(grid))
    failures = read_table(work / "results/tables/failures.csv", keep_default_na=False)
    calibration = failures[failures["stage"] == "calibration"]
    assert len(calibration) and calibration["error"].str.contains(why).any()
    assert calibration["error"].str.contains("calibration.group_by: flight").all()
    comparison = read_table(work / "results/tables/comparison.csv", keep_default_na=False)
    on_all = comparison[comparison["subset"] == "all"].set_index("method")
    # a run not scored has its row, as comparison.md lists it
    uncalibrated = set(on_all.index[on_all["flights"] == 0])
    assert uncalibrated and uncalibrated <= set(calibration["method"])
    assert set(on_all.loc[list(uncalibrated), "not_ranked"]) == {"not scored"}
    assert set(on_all.loc[list(uncalibrated), "accuracy"]) == {""}
    text = (work / "results/tables/comparison.md").read_text()
    assert all(f"`{m}` on `all`: all" in text for m in uncalibrated)
    assert (work / "paper/build/paper.md").exists()
    if not any("no_failure" in name for name in specs):
        grid_table = (work / "results/tables/detectability.md").read_text()
        assert grid_table.startswith("No injected sensor fault was scored")


@pytest.mark.parametrize("config, message", [
    ("calibration: {group_by: week, margin_s: 1.0}",
     "'week' is not one of ['date', 'recording', 'flight']"),
    ("strict: maybe", "'maybe' is not of type 'boolean'"),
    ("methods: {x: {detector: rls_arx_zscor}}", "config methods.x: \"unknown detector"),
    ("methods: {x: {detector: rls_arx_zscore, params: {zthreshold: 3}}}",
     "config methods.x: detector 'rls_arx_zscore' has no parameter 'zthreshold'"),
    ("methods: {x: {detector: pyod, params: {model: IsolationTree}}}",
     "config methods.x: pyod model 'IsolationTree' with params {} cannot be built"),
    ("methods: {x: {detector: nested_selection, params: {detector: pyod, params: {model: "
     "HBOS}, grid: {params: [{n_bins: 5}, {n_binz: 10}]}}}}",
     "config methods.x: nested selection of 'pyod': grid candidate {'params': {'n_binz': "
     "10}}: pyod model 'HBOS'"),
    ("methods: {x: {detector: residual_logistic, calibration: {group_by: recording}}}",
     "config methods.x: calibration.group_by: recording lets flights of the scored date "
     "train it, so it can only be a reference row (role: reference)"),
    ("calibration: {group_by: flight, margin_s: 1.0}",
     "calibration.group_by: flight lets flights of the scored date train it"),
])
def test_a_wrong_config_value_is_named_before_any_job_runs(corpus, tmp_path, config, message):
    (tmp_path / "bad.yaml").write_text(config + "\n")
    done = run_workflow(tmp_path, corpus.parent, "-n", "--configfile",
                        str(REPO / "config/config.yaml"), str(tmp_path / "bad.yaml"), ok=False)
    assert message in done.stderr + done.stdout


def test_lint_asks_only_for_per_rule_software_environments(corpus, tmp_path):
    """Packages are pinned by constraints.txt and installed by the README's command, so
    the per-rule conda/container lint is the one accepted; any other lint fails here."""
    done = run_workflow(tmp_path, corpus.parent, "--lint", ok=False)
    titles = {line.strip() for line in done.stderr.splitlines() if line.startswith("    * ")}
    assert titles == {"* Specify a conda environment or container for each rule.:"}


def _has_value(key: str, tables: dict) -> bool:
    """Whether the run's tables hold the number that paper key ``key`` quotes."""
    kind, *args = key.split(":")
    comparison, by_fault = tables["comparison"], tables["by_fault"]
    columns = {"precision": "precision", "recall": "recall", "accuracy": "accuracy",
               "accuracypaper": "accuracy_paper", "recallpaper": "recall_paper",
               "meandet": "mean_detection_s", "maxdet": "max_detection_s",
               "detected": "tp", "falsealarms": "fault_free_flights"}
    if kind in columns:
        m, s = args
        row = comparison[(comparison["method"] == m) & (comparison["subset"] == s)]
        return bool(len(row)) and row[columns[kind]].notna().all()
    if kind == "classdetected":
        m, s, c = args
        return bool(((by_fault["method"] == m) & (by_fault["subset"] == s)
                     & (by_fault["fault_class"] == c)).any())
    if kind in ("marginmax", "marginmin"):
        rows = tables["per_flight"]
        rows = rows[(rows["method"] == args[0]) & (rows["fault_class"] == args[1])]
        return rows["margin_in_time"].notna().any()
    if kind == "step":
        leak = tables["leakage"]
        return bool(((leak["signal"] == args[0]) & (leak["fault_class"] == args[1])
                     & (leak["emergency_trajectory"] == (args[2] == "emr"))).any())
    return False


def test_the_paper_has_no_gap_where_the_tables_hold_the_number(runs):
    """Every "n/a" of the rendered paper stands where the run's tables have no such
    number (section 5's per-class counts once read n/a over a full by_fault table)."""
    from alfa_bench.outputs.paper import paper_numbers
    out = runs[0] / "results/tables"
    tables = {n: read_table(out / f"{n}.csv") for n in
              ("comparison", "by_fault", "per_flight", "leakage", "sweep")}
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    numbers = paper_numbers(tables["comparison"], tables["sweep"], tables["leakage"],
                            tables["by_fault"], tables["per_flight"],
                            methods=list(config["methods"]), subsets=config["subsets"],
                            primary=config["primary_subset"])
    template = re.sub(r"<!--.*?-->", "", (REPO / "paper/paper.template.md").read_text(),
                      flags=re.S)
    quoted = re.findall(r"\{\{num:([^}]+)\}\}", template)
    gaps = [k for k in dict.fromkeys(quoted) if numbers[k] == "n/a" and _has_value(k, tables)]
    assert not gaps, gaps


def test_a_failed_download_ends_on_what_to_do_without_a_traceback(tmp_path):
    """No network (a closed loopback port): the terminal shows the download's message,
    what to do, once and with no traceback; the log keeps the details."""
    import socket
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]          # closed once the socket is
    config = tmp_path / "offline.yaml"
    config.write_text(yaml.safe_dump({"download": {
        "api": f"http://127.0.0.1:{port}/files", "file": "processed.zip",
        "md5": "0" * 32, "sha256": None, "dest": "resources/alfa"}}))
    done = run_workflow(tmp_path, None, "--configfile", str(REPO / "config/config.yaml"),
                        str(config), target="results/flights.csv", ok=False)
    assert done.stderr.count("download_alfa: cannot reach") == 1, done.stderr
    assert "Traceback" not in done.stderr and "set ALFA_DIR" in done.stderr, done.stderr
    log = (tmp_path / "results/logs/download_alfa.log").read_text()
    assert "Traceback" in log and "cannot reach" in log


#: Snakemake's own closing lines after a failed job (the onerror message comes before)
SNAKEMAKE_FOOTER = ("Complete log", "Elapsed time", "WorkflowError:",
                    "At least one job did not complete")


def _last_lines(done: subprocess.CompletedProcess, footer: bool = False) -> list[str]:
    lines = [line for line in (done.stdout + done.stderr).splitlines() if line.strip()]
    if footer:
        lines = [line for line in lines if not line.startswith(SNAKEMAKE_FOOTER)]
    return lines[-2:]


@pytest.mark.parametrize("layout, said", [
    ({}, "which has no processed/ folder: it holds 1 entry (flights.zip)"),
    ({"processed/notes.txt": ""}, "no entry of its processed/ is a flight folder (1 entry; "
                                  "the first, notes.txt: not a flight folder: a file)"),
])
def test_an_alfa_dir_that_is_not_alfas_ends_on_what_to_do(tmp_path, layout, said):
    alfa = tmp_path / "alfa"
    (alfa / "flights.zip").parent.mkdir()
    if not layout:
        (alfa / "flights.zip").write_text("")
    for path, text in layout.items():
        (alfa / path).parent.mkdir(parents=True, exist_ok=True)
        (alfa / path).write_text(text)
    done = run_workflow(tmp_path / "work", alfa, "-n", ok=False)
    last = _last_lines(done)
    assert last[0] == f"ALFA_DIR is {alfa}, {said}." or last[0] == f"ALFA_DIR is {alfa}: {said}."
    assert last[1].startswith("What to do: set ALFA_DIR to the folder that holds ALFA's "
                              "processed/"), last
    assert "Traceback" not in done.stderr


def test_a_processed_folder_without_a_flight_that_reads_ends_on_what_to_do(tmp_path):
    """A folder named and shaped as a flight whose files do not parse: the manifest job
    fails, and the run's last words before Snakemake's own say so."""
    name = "carbonZ_2018-07-18-15-53-31_1_engine_failure"
    flight = tmp_path / "alfa/processed" / name
    flight.mkdir(parents=True)
    (flight / f"{name}-mavros-nav_info-roll.csv").write_text("not,a\nflight\n")
    done = run_workflow(tmp_path / "work", tmp_path / "alfa", target="results/flights.csv",
                        ok=False)
    last = _last_lines(done, footer=True)
    assert last[0].startswith("What to do: set ALFA_DIR to the folder that holds ALFA's "
                              "processed/"), last
    assert last[1] == "Details: results/logs/manifest.log", last
    assert f"ALFA_DIR is {tmp_path / 'alfa'}: no flight under its processed/ can be read" in (
        done.stderr)


def test_a_local_run_selects_its_jobs_without_a_rate_limit(corpus, tmp_path):
    """Snakemake's default rate limit re-runs its job selection from a timer that each
    pass and each job event start anew (rules/common.smk's onstart): a local run sets
    it aside, so that the jobs a selection may start are never counted down from it."""
    done = run_workflow(tmp_path, corpus.parent, "--verbose", target="results/flights.csv",
                        quiet=False)
    counts = re.findall(r"Resources after job selection: .*'_job_count': (\d+)", done.stderr)
    assert counts and set(counts) == {str(sys.maxsize)}, counts


def test_a_misspelt_config_key_ends_on_the_key_and_the_keys_allowed(corpus, tmp_path):
    (tmp_path / "bad.yaml").write_text("scoring:\n  deadine_s: 5.0\n")
    done = run_workflow(tmp_path, corpus.parent, "-n", "--configfile",
                        str(REPO / "config/config.yaml"), str(tmp_path / "bad.yaml"), ok=False)
    assert _last_lines(done) == [
        f"config: unknown key 'deadine_s' under scoring (in {tmp_path / 'bad.yaml'}). "
        "Did you mean 'deadline_s'?", "Allowed there: deadline_s, deadlines_s."]
    assert "$schema" not in done.stderr + done.stdout


def test_every_csv_reads_plainly_with_its_documented_header(runs):
    """pandas' and DuckDB's defaults read each CSV with the header docs/outputs.md lists
    (a one-line provenance comment once made pandas see 410 columns)."""
    import duckdb
    import pandas as pd
    documented = dict(re.findall(r"^- `([^`]+\.csv)`: (.+)$", (REPO / "docs/outputs.md")
                                 .read_text(), flags=re.M))
    work = runs[0]
    found = sorted(p for p in (work / "results").rglob("*.csv")
                   if "detections" not in p.parts and "parts" not in p.parts)
    # results/corpus/ is written on a corpus of logs only (tests/test_own_flights.py)
    assert {p.relative_to(work).as_posix() for p in found} == {
        d for d in documented if not d.startswith("results/corpus/")}
    # a run's part of a table is its rows of it: the table's header
    parts = sorted((work / "results/parts").glob("*/*.csv"))
    assert {p.parent.name for p in parts} == {"sweep", "detectability", "isolation_sensors",
                                              "isolation_actuators"}
    for path in parts:
        table = f"results/tables/{path.parent.name}.csv"
        assert list(pd.read_csv(path).columns) == re.findall(r"`([^`]+)`",
                                                             documented[table]), path
    for path in found:
        header = re.findall(r"`([^`]+)`", documented[path.relative_to(work).as_posix()])
        frame = pd.read_csv(path)
        assert list(frame.columns) == header, path
        if len(frame):          # a header alone is no table DuckDB can sniff a header in
            table = duckdb.sql(f"select * from read_csv_auto('{path}')")
            assert table.columns == header and len(table.fetchall()) == len(frame), path
    for path in (work / "results/detections").glob("*/failures.csv"):
        assert list(pd.read_csv(path).columns) == re.findall(
            r"`([^`]+)`", documented["results/load_failures.csv"])[:-1], path


@pytest.fixture(scope="module")
def damaged(corpus, overlay, tmp_path_factory):
    """`snakemake all --keep-going` over the corpus plus one flight of each kind of
    damage: the run's folder, the damaged flights, and those refused at load."""
    root = tmp_path_factory.mktemp("damaged")
    processed = root / "processed"
    shutil.copytree(corpus, processed)

    def flight(name, **kw):
        return write_flight(processed, name, seed=len(list(processed.iterdir())) + 20, **kw)

    nan_cell = flight("carbonZ_2018-07-30-16-39-00_3_no_failure")
    edit(ROLL, lambda ls: ls[:7] + [set_cell(ls[7], 5, "nan")] + ls[8:])(nan_cell)
    late = flight("carbonZ_2018-09-11-14-22-07_1_engine_failure", onset_s=50.0)
    edit(IMU, _late_start)(late)
    onset_out = flight("carbonZ_2018-09-11-11-56-30_engine_failure", onset_s=50.0)
    edit(GT, lambda ls: ls[:1] + [shift_time(line, 35 * 10**9) for line in ls[1:]])(onset_out)
    spike = flight("carbonZ_2018-10-05-14-34-20_2_no_failure")
    edit(IMU, lambda ls: ls[:9] + [set_cell(ls[9], 4, "1e12")] + ls[10:])(spike)
    bom = flight("carbonZ_2018-07-18-16-37-39_2_no_failure")
    path = bom / f"{bom.name}-{ROLL}.csv"
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    os.symlink(root / "gone", processed / "carbonZ_2018-09-11-14-41-51_elevator_failure")
    write_flight(processed, "not_an_alfa_name", onset_s=50.0)
    # what a user met, one of each on a day: a topic only some runs read going back in
    # time, a word in a number's cell, an empty cell, a missing topic file; and an
    # empty file and a gap of seconds
    back = flight("carbonZ_2018-09-11-14-16-55_no_failure")
    edit(YAW, lambda ls: ls[:3] + [ls[4], ls[3]] + ls[5:])(back)
    word = flight("carbonZ_2018-09-11-15-06-34_1_rudder_right_failure", onset_s=45.0,
                  fault_topic="failure_status-rudder", code=1)
    edit(WIND, lambda ls: ls[:5] + [set_cell(ls[5], 4, "abc")] + ls[6:])(word)
    empty = flight("carbonZ_2018-09-11-14-41-38_no_failure")
    edit(ROLL, lambda ls: ls[:7] + [set_cell(ls[7], 5, "")] + ls[8:])(empty)
    gone = flight("carbonZ_2018-09-11-17-55-30_1_right_aileron_failure", onset_s=50.0,
                  fault_topic="failure_status-aileron", code=1)
    topic_file(gone, ERRORS).unlink()
    unreadable = flight("carbonZ_2018-09-11-14-22-07_2_no_failure")
    topic_file(unreadable, ROLL).write_text("")
    gap = flight("carbonZ_2018-10-05-15-55-10_elevator_failure", onset_s=40.0,
                 fault_topic="failure_status-elevator")
    edit(IMU, _gap)(gap)
    work = root / "run"
    work.mkdir()
    done = run_workflow(work, processed.parent, "--keep-going", "--configfile",
                        str(REPO / "config/config.yaml"), str(overlay))
    refused = {onset_out.name, spike.name, "not_an_alfa_name", nan_cell.name, late.name,
               "carbonZ_2018-09-11-14-41-51_elevator_failure", back.name, word.name,
               empty.name, gone.name, unreadable.name, gap.name}
    return work, refused | {bom.name}, refused, done


def test_a_corpus_of_every_damage_runs_to_the_end_and_scores_every_clean_flight(damaged,
                                                                               corpus):
    work, _, refused, _ = damaged
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    clean = {p.name for p in corpus.iterdir()}
    for method in config["methods"]:
        scored = {p.stem for p in (work / "results/detections" / method).glob("*.json")}
        assert clean <= scored, method
        assert not scored & refused
    failures = read_table(work / "results/tables/failures.csv", keep_default_na=False)
    why = failures.groupby("flight")["error"].apply(" | ".join)
    assert "outside the recorded data" in why["carbonZ_2018-09-11-11-56-30_engine_failure"]
    assert "outside what roll_rate can read" in why["carbonZ_2018-10-05-14-34-20_2_no_failure"]
    assert "starts 30.5 s after" in why["carbonZ_2018-09-11-14-22-07_1_engine_failure"]
    assert "a broken link" in why["carbonZ_2018-09-11-14-41-51_elevator_failure"]
    assert "not an ALFA flight name" in why["not_an_alfa_name"]
    assert "empty or NaN cell" in why["carbonZ_2018-07-30-16-39-00_3_no_failure"]
    assert "timestamps go backwards" in why["carbonZ_2018-09-11-14-16-55_no_failure"]
    assert "non-numeric cell 'abc'" in why["carbonZ_2018-09-11-15-06-34_1_rudder_right_failure"]
    assert "topic file is missing" in why["carbonZ_2018-09-11-17-55-30_1_right_aileron_failure"]
    assert "empty file" in why["carbonZ_2018-09-11-14-22-07_2_no_failure"]
    assert "held longer than 1.0 s" in why["carbonZ_2018-10-05-15-55-10_elevator_failure"]
    recorded = {p.stem for p in (work / "results/rerun/_flight").glob("*.rrd")}
    assert clean - {p for p in clean if "no_ground_truth" in p} <= recorded


def test_a_damaged_flight_moves_no_clean_flight_but_through_calibration(damaged, runs, corpus):
    """The clean flights' outcomes equal a run without the damaged flights, or differ
    only where a damaged flight the checks accepted (a repair) calibrated them, as the
    record says; a refused flight calibrates nothing."""
    work, damaged_flights, refused, _ = damaged
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    for method in config["methods"]:
        for flight in sorted(p.name for p in corpus.iterdir()):
            a = runs[0] / "results/detections" / method / f"{flight}.json"
            if not a.exists():
                continue
            before, after = json.loads(a.read_text()), json.loads(
                (work / "results/detections" / method / f"{flight}.json").read_text())
            used = set((after.get("calibration") or {}).get("flights", []))
            assert not used & refused, (method, flight)
            if before["first_alarm_s"] != after["first_alarm_s"]:
                assert used & damaged_flights, (method, flight)


def test_every_run_scores_the_same_flights_and_every_output_names_those_left_out(damaged):
    """A flight any catalogue signal cannot be read on is refused at load, for every run:
    every run scores the same flights, and the ranking is the common ground's, stated
    with the same counts on the page, in the comparison and in the paper, naming the
    flights left out; Snakemake's output ends on a line saying so."""
    work, _, refused, done = damaged
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    scored = {m: frozenset(p.stem for p in (work / "results/detections" / m).glob("*.json"))
              for m in config["methods"]}
    assert len(set(scored.values())) == 1, scored
    failures = read_table(work / "results/tables/failures.csv", keep_default_na=False)
    assert set(failures["stage"]) == {"load"} and set(failures["flight"]) == refused
    left_out = read_table(work / "results/tables/left_out.csv", keep_default_na=False)
    assert set(left_out["flight"]) == refused and set(left_out["runs"]) == {"every run"}
    manifest = read_table(work / "results/flights.csv", keep_default_na=False)
    summary = read_table(work / "results/tables/summary.csv").set_index(["method", "subset"])
    comparison = read_table(work / "results/tables/comparison.csv")
    page = (work / "results/index.html").read_text()
    paper = (work / "paper/build/paper.md").read_text()
    for subset in ("all", "no_emr"):
        labelled = sum(subset in s.split(";") for s in manifest["subsets"])
        gone = sum(subset in str(s).split(";") for s in left_out["subsets"])
        for method in config["methods"]:
            row = summary.loc[(method, subset)]
            assert (row["flights"], row["excluded"]) == (labelled, gone), (method, subset)
        rows = comparison[comparison["subset"] == subset]
        assert rows["rank"].notna().sum() > 3 and (rows["flights"] == labelled).all()
        said = f"{labelled + gone} flights, {labelled} on the common ground, {gone} left out"
        assert said in paper and said in (work / "results/tables/comparison.md").read_text()
        if subset == "no_emr":
            assert said in page
    for flight in left_out.loc[left_out["subsets"].str.contains("no_emr"), "flight"]:
        assert flight in page and flight in paper
    assert "| excluded |" in (work / "results/tables/summary.md").read_text()
    # last, after Snakemake's own closing lines (the log's path, the time taken): then
    # the page to open, with the runs it ranks and those it does not
    headline = comparison[comparison["subset"] == "no_emr"]
    ranked = int(headline["rank"].notna().sum())
    assert done.stderr.strip().splitlines()[-2:] == [
        f"alfa-bench: {len(refused)} flight(s) left out of the common ground every run is "
        f"ranked on: {len(refused)} refused at load, 0 failed by 0 run(s); {len(failures)} "
        "error(s) in results/tables/failures.csv, the flights in results/tables/left_out.csv",
        f"alfa-bench: open results/index.html: {ranked} run(s) ranked on `no_emr`, "
        f"{len(headline) - ranked} not ranked (each with why, on the page)",
    ], done.stderr


def test_a_misspelt_signal_in_a_config_run_stops_the_dry_run(corpus, tmp_path):
    """A typo is the config's error: it stops `snakemake -n` naming the run, instead of
    excluding every flight as bad data."""
    config = tmp_path / "typo.yaml"
    config.write_text(yaml.safe_dump({"methods": {"typo": {
        "detector": "rls_arx_zscore",
        "params": {"pairs": [{"name": "roll", "input": "roll_cmdd", "output": "roll"}]}}}}))
    done = run_workflow(tmp_path, corpus.parent, "-n", "--configfile",
                        str(REPO / "config/config.yaml"), str(config), ok=False)
    assert "config methods.typo: unknown signal(s) ['roll_cmdd']" in done.stdout + done.stderr


def test_a_run_taken_out_of_the_config_is_named_removable_and_never_compared(runs, corpus,
                                                                            tmp_path):
    """A result folder no configured run writes: the dry run names it, `snakemake
    remove_stale` removes it, and `compare` (given the checkout's root) ranks the
    published config's runs only."""
    import alfa_bench as ab

    work = tmp_path / "checkout"
    shutil.copytree(runs[0] / "results", work / "results",
                    ignore=shutil.ignore_patterns("rerun*", "figure*", "traces", "cache"))
    shutil.copytree(work / "results/detections/silent", work / "results/detections/gone_run")
    result = ab.evaluate("silent", ab.load_corpus(corpus.parent, cache=tmp_path / "cache"),
                         name="mine")
    table = ab.compare(result, published=work)
    assert "mine" in set(table["method"]) and "silent" in set(table["method"])
    assert "gone_run" not in set(table["method"])
    config = ["--configfile", str(REPO / "config/config.yaml")]
    dry = run_workflow(work, corpus.parent, "-n", *config, quiet=False)
    assert ("no configured run writes any more, e.g. results/detections/gone_run"
            in dry.stdout + dry.stderr)
    run_workflow(work, corpus.parent, *config, target="remove_stale")
    assert not (work / "results/detections/gone_run").exists()
    assert (work / "results/detections/silent").is_dir()


def _parts_job(work: Path, method: str, to: Path) -> tuple[dict, list[str]]:
    """The parts job of ``method`` in the run ``work``, writing to ``to``: its outputs
    (by table, relative to ``to``) and its command's arguments."""
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    primary = config["primary_subset"]
    out = {"sweep": "sweep/m.csv", "per_flight": "per_flight/m.jsonl",
           "records": "records/m.jsonl", "detectability": "detectability/m.csv",
           "isolation_sensors": "isolation_sensors/m.csv",
           "isolation_actuators": "isolation_actuators/m.csv"}
    argv = [method, "--manifest", str(work / "results/flights.csv"),
            "--detections", str(work / f"results/detections/{method}"),
            "--traces", str(work / f"results/traces/{method}"),
            "--recordings", str(to / "rerun"), "--log", str(to / "log"),
            "--subsets", json.dumps([primary, *(s for s in config["subsets"] if s != primary)]),
            "--deadline-s", str(config["scoring"]["deadline_s"]),
            "--injected-manifest", str(work / "results/injected/flights.csv"),
            "--injected", str(work / f"results/injected/detections/{method}"),
            *(a for k, v in out.items() for a in (f"--{k.replace('_', '-')}", str(to / v)))]
    return out, argv


def test_a_parts_job_forked_from_its_server_writes_what_it_writes_alone(runs, tmp_path):
    """The run's parts jobs forked from the parts server (the local run); the job of a
    run scored on the injected grid, run again in a process of its own as a cluster
    runs it, writes the same parts byte for byte and the same recordings."""
    from recordings import content

    from alfa_bench.workflow import parts_job

    work, method = runs[0], "glrt_arx"
    out, argv = _parts_job(work, method, tmp_path)
    os.environ.pop(parts_job.SERVER_ENV, None)
    assert parts_job.main(argv) == 0
    for table, path in out.items():
        made = work / f"results/parts/{table}/{method}{Path(path).suffix}"
        assert (tmp_path / path).read_bytes() == made.read_bytes(), table
    recordings = sorted((work / f"results/rerun/{method}").glob("*.rrd"))
    assert recordings and [p.name for p in recordings] == sorted(
        p.name for p in (tmp_path / "rerun").glob("*.rrd"))
    for p in recordings:
        assert content(p) == content(tmp_path / "rerun" / p.name), p.name


def test_a_parts_job_imports_no_scipy_module_its_server_did_not_preload(runs, tmp_path):
    """Every parts job is a fork of the parts server: a module it first imports in the
    fork (scipy.special for the sweep's intervals took a quarter of a second) is paid
    by each job of every run, where the server's preload pays it once."""
    from alfa_bench.workflow import parts_job

    _, argv = _parts_job(runs[0], "glrt_arx", tmp_path)
    code = ("import json, sys\n"
            "from alfa_bench.workflow import parts_job\n"
            "parts_job.preload()\n"
            "before = set(sys.modules)\n"
            "assert parts_job.main(json.loads(sys.argv[1])) == 0\n"
            "print(json.dumps(sorted(set(sys.modules) - before)))\n")
    env = {k: v for k, v in os.environ.items() if k != parts_job.SERVER_ENV}
    done = subprocess.run([sys.executable, "-c", code, json.dumps(argv)], env=env,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    late = json.loads(done.stdout.splitlines()[-1])
    assert not [m for m in late if m.split(".")[0] == "scipy"], late


def test_a_script_forked_from_its_server_writes_what_it_writes_alone(runs, overlay, tmp_path):
    """The run's scripts forked from the script server (the local run, of many script
    jobs); the deadline's and the tables' scripts, each forced again alone in a copy of
    the run (one script job: a process of its own, as a cluster runs it), write the same
    files byte for byte."""
    work = tmp_path / "run"
    shutil.copytree(runs[0], work, symlinks=True)
    server_log = work / "results/logs/script_server.log"
    forked = server_log.read_text()
    for rule in ("deadline", "tables"):
        assert f"{rule}.py: forked" in forked
    server_log.unlink()
    start = {p: p.stat().st_mtime_ns for p in (work / "results").rglob("*") if p.is_file()}
    for rule, target in (("deadline", "results/tables/deadline.csv"),
                         ("tables", "results/tables/summary.csv")):
        run_workflow(work, None, "--configfile", str(REPO / "config/config.yaml"),
                     str(overlay), "--forcerun", rule, target=target)
    assert not server_log.exists()
    written = sorted(p.relative_to(work) for p in (work / "results").rglob("*")
                     if p.is_file() and p.stat().st_mtime_ns != start.get(p)
                     and not {"logs", "benchmarks"} & set(p.relative_to(work).parts))
    assert {"results/figures/deadline.png", "results/tables/comparison.csv"} <= {
        str(p) for p in written}
    for rel in written:
        assert (work / rel).read_bytes() == (runs[0] / rel).read_bytes(), rel
