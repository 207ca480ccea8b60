"""The manuscript quotes only what the run produced, in both of its forms."""

import io
import re
from pathlib import Path

import pandas as pd
import pytest

from alfa_bench.outputs.paper import latex_keys, latex_macros, paper_numbers, render_markdown
from alfa_bench.outputs.tables import comparison_latex

REPO = Path(__file__).resolve().parent.parent
TEX = (REPO / "paper/paper.tex").read_text()
MARKDOWN = re.sub(r"<!--.*?-->", "", (REPO / "paper/paper.template.md").read_text(),
                  flags=re.S)


def comparison(**overrides):
    row = {"subset": "all", "method": "a", "block": "honest", "rank": 2, "detector": "d",
           "calibration": "none", "deadline_s": 5.0, "flights": 10, "tp": 2, "fp": 2,
           "fn": 5, "tn": 2, "precision": 0.5, "recall": 0.25, "accuracy": 0.4,
           "mean_detection_s": 1.5, "max_detection_s": float("nan"), "accuracy_paper": 0.7,
           "recall_paper": 0.8, "mean_detection_s_paper": 6.0,
           "fault_free_flights": 3, "fault_free_false_alarms": 1, "armed_flights": 10,
           "excluded": 1, "vs_best_only_this": 0, "vs_best_only_best": 2, "vs_best_p": 0.5}
    rows = [row, {**row, "method": "b", "accuracy": 0.6, "rank": 1, "vs_best_p": float("nan")},
            {**row, "method": "c", "accuracy": 0.9, "block": "reads actuators",
             "rank": float("nan"), "vs_best_p": 0.01}]
    return pd.DataFrame([{**r, **overrides} for r in rows])


def leakage():
    return pd.DataFrame({"signal": ["servo_throttle", "roll", "roll_cmd", "roll_cmd"],
                         "fault_class": ["engine"] * 4,
                         "emergency_trajectory": [False, False, False, True],
                         "flights": [20, 20, 7, 13], "flat_at_onset": [20, 0, 0, 0],
                         "flat_chance_before": [0.1, float("nan"), 0.0, 0.0],
                         "flat_chance_fault_free": [0.15, 0.0, 0.0, 0.0],
                         "step_at_onset": [20, 1, 1, 5], "step_flights": [20, 20, 7, 13]})


def sweep():
    return pd.DataFrame({"method": ["a", "a", "b"], "subset": ["all"] * 3,
                         "fp": [0, 2, 1], "recall": [0.1, 0.9, 0.8]})


def test_numbers_come_from_the_tables():
    n = paper_numbers(comparison(), sweep(), leakage())
    assert n["accuracy:a:all"] == "40.00" and n["maxdet:a:all"] == "n/a"
    # the best is the top honest method, never a marked one, however accurate
    assert n["best:all"] == "b" and n["bestaccuracy:all"] == "60.00"
    assert n["tied:all"] == "a" and n["accuracypaper:a:all"] == "70.00"
    assert n["detected:a:all"] == "2 of 7" and n["deadline"] == "5"
    assert n["leak:servo_throttle:engine"] == "20 of 20"
    assert n["leakchance:servo_throttle:engine"] == "15.00"
    assert n["leakchance:roll:engine"] == "0.00"
    assert n["leak:servo_elevator:elevator"] == "n/a"    # no elevator flight here
    assert n["leak:roll_cmd:engine"] == "0 of 20"        # both groups together
    assert (n["step:roll_cmd:engine:emr"], n["step:roll_cmd:engine:noemr"]) == ("5 of 13",
                                                                                 "1 of 7")
    assert n["falsealarms:a:all"] == "1 of 3"
    assert n["recallnofa:a:all"] == "10.00" and n["recallnofa:b:all"] == "n/a"
    assert n["paper:accuracy"] == "86.36"


def test_the_subsets_size_is_its_common_ground_and_a_run_not_scored_quotes_na():
    """A reference run that failed on flights scored fewer than the common ground, and
    comes last; a run that scored none has a row without scores: neither sets the
    subset's numbers, and the one not scored quotes "n/a"."""
    table = comparison()
    read_back = pd.concat([table, pd.DataFrame([
        {**table.iloc[0].to_dict(), "method": "r", "block": "reference", "flights": 7,
         "tp": 1, "fn": 3, "fault_free_flights": 3, "failed_flights": 3},
        {"subset": "all", "method": "z", "block": "", "deadline_s": 5.0, "flights": 0,
         "excluded": 1, "failed_flights": 10, "not_ranked": "not scored"}])])
    # as paper.smk reads comparison.csv: the empty cells make its counts floats
    read_back = pd.read_csv(io.StringIO(read_back.to_csv(index=False)))
    n = paper_numbers(read_back, sweep(), leakage(), methods=["a", "r", "z"],
                      subsets=["all"])
    assert (n["flights:all"], n["faultflights:all"], n["faultfree:all"]) == ("10", "7", "3")
    assert n["detected:r:all"] == "1 of 4" and n["detected:a:all"] == "2 of 7"
    assert n["accuracy:z:all"] == n["detected:z:all"] == "n/a"


def test_per_class_numbers_come_from_the_by_fault_table():
    by_fault = pd.DataFrame({"method": ["a"] * 3, "subset": ["all"] * 3,
                             "fault_class": ["engine", "none", "total"],
                             "flights": [4, 2, 6], "detected": [3, 0, 3]})
    n = paper_numbers(comparison(), sweep(), leakage(), by_fault)
    assert n["classdetected:a:all:engine"] == "3 of 4"
    # the configured runs and subsets, as the workflow passes them, keep the numbers
    n = paper_numbers(comparison(), sweep(), leakage(), by_fault, methods=["a", "z"],
                      subsets=["all", "no_emr"])
    assert n["classdetected:a:all:engine"] == "3 of 4"
    assert n["classdetected:z:no_emr:engine"] == "n/a"
    assert n["classdetected:a:all:aileron"] == "n/a"     # no aileron flight here
    assert "classdetected:a:all:none" not in n and "classdetected:a:all:total" not in n


def test_margins_come_from_the_per_flight_table():
    per_flight = pd.DataFrame({"method": ["a"] * 3, "fault_class": ["engine", "engine", "none"],
                               "margin_in_time": [0.64, 1.83, float("nan")],
                               "margin_before": [0.3, 1.2, 2.18]})
    n = paper_numbers(comparison(), sweep(), leakage(), None, per_flight)
    assert n["marginmax:a:engine"] == "1.83" and n["marginmin:a:engine"] == "0.64"
    assert n["marginbefore:a"] == "2.18" and n["marginmax:a:aileron"] == "n/a"


def test_markdown_refuses_unknown_keys_and_missing_files(tmp_path):
    (tmp_path / "t.md").write_text("| x |\n")
    text = render_markdown("<!-- {{num:ignored}} -->A {{num:k}} {{file:t.md}}", {"k": "1"},
                           tmp_path)
    assert text == "A 1 | x |"
    with pytest.raises(KeyError, match="nope"):
        render_markdown("{{num:nope}}", {}, tmp_path)
    with pytest.raises(FileNotFoundError, match="gone.md"):
        render_markdown("{{file:gone.md}}", {}, tmp_path)


def test_latex_macros_define_every_key_and_stop_on_unknown_ones():
    macros = latex_macros({"accuracy:rls_arx:all": "4.55", "best:all": "ffrls_monitor"})
    assert r"\csname abresult@accuracy:rls_arx:all\endcsname{4.55}" in macros
    assert r"{ffrls\_monitor}" in macros
    assert r"\errmessage" in macros
    assert latex_keys("% \\result{commented}\n\\result{a:b} 50\\% \\result{c}") == {"a:b", "c"}


def test_the_twins_quote_the_same_results_and_include_the_same_outputs():
    md_keys = set(re.findall(r"\{\{num:([^}]+)\}\}", MARKDOWN))
    assert md_keys and md_keys == latex_keys(TEX)
    md_files = {Path(f).stem for f in re.findall(r"\{\{file:([^}]+)\}\}", MARKDOWN)}
    md_files |= {Path(f).stem for f in re.findall(r"\]\(([^)]+\.png)\)", MARKDOWN)}
    tex_files = {Path(f).stem for f in re.findall(r"\\(?:input|includegraphics)(?:\[[^]]*\])?"
                                                  r"\{(results/[^}]+)\}", TEX)}
    assert md_files == tex_files


def test_every_quoted_key_is_one_the_numbers_define():
    """With the configured methods and subsets, every key the manuscript quotes exists."""
    import yaml
    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    rows = [{**comparison().iloc[0].to_dict(), "method": m, "subset": s}
            for m in config["methods"] for s in config["subsets"]]
    sweeps = pd.DataFrame([{"method": m, "subset": s, "fp": 0, "recall": 0.0}
                           for m in config["methods"] for s in config["subsets"]])
    # every catalogue signal and fault class, as the leakage audit writes them
    from alfa_bench.analysis.blocks import FAULT_ORDER
    from alfa_bench.data import SIGNALS
    leak = pd.DataFrame([{**leakage().iloc[0].to_dict(), "signal": sig, "fault_class": c}
                         for sig in SIGNALS for c in FAULT_ORDER if c != "none"])
    assert latex_keys(TEX) <= set(paper_numbers(pd.DataFrame(rows), sweeps, leak))


def test_latex_tables_escape_and_label():
    tex = comparison_latex(comparison())
    assert r"\label{tab:comparison-1}" in tex and r"\texttt{all}" in tex
    assert "\\toprule" in tex and tex.count(r"\begin{table}") == 1
    assert (" & 50.0 & 25.0 & 40.0 & 2 (not resampled) & - & 1.50 & - & 70.00 & 6.00 & "
            "1 of 3 & - & "
            "0 / 2, p = 0.500 "
            "(cannot tell apart) & 10 & 1 \\\\") in tex
    assert "MARKED: reads what the fault emulation writes" in tex
    assert ("(11 flights, 10 on the common ground, 1 left out; includes the "
            "emergency-trajectory flights, whose commands switch at onset; deadline 5.0 s)"
            ) in tex


def test_sensor_fault_numbers_come_from_the_grid_and_the_isolation_tables():
    from alfa_bench.outputs.paper import sensor_numbers
    grid = pd.DataFrame({"method": ["a", "a", "b"], "flights": [4, 4, 8],
                         "detected": [4, 2, 2], "chance_rate": [0.5, 0.0, 0.0]})
    iso = pd.DataFrame({"method": ["a", "a", "b", "b"], "flight": ["x", "y", "x", "y"],
                        "correct": [True, False, False, False]})
    n = sensor_numbers({"detectability": grid, "isolation_sensors": iso}, ["a", "b", "c"])
    assert n["sensordetected:a"] == "75.00" and n["sensorchance:a"] == "25.00"
    assert n["bestsensor"] == "a" and n["sensorfaults"] == "2"
    assert n["sensorisolated:a"] == "50.00" and n["sensorisolated:c"] == "n/a"
    assert n["actuatorisolated:a"] == "n/a"


#: settings, not results: the intervals' confidence level and the audit's quantile
_TYPED_SETTINGS = {"95"}


def _typed_results(text: str, percent: str) -> list[str]:
    """Counts and rates typed in prose: ``k %``, ``k of n``, ``k flights``/``faults``."""
    found = re.findall(rf"\b(\d+(?:\.\d+)?)\s*{percent}", text)
    found += re.findall(r"\b\d+ of \d+\b", text)
    found += re.findall(r"\b\d+~?\s*(?:labelled |fault-free |engine |fault )?"
                        r"(?:flights?|faults?)\b", text)
    return [f for f in found if f not in _TYPED_SETTINGS]


def test_the_prose_types_no_count_or_rate():
    """Every count and rate of the manuscript is quoted by key (the abstract once typed
    "the 22 flights of that paper", wrong on any other flight set); equations, code
    and references aside."""
    md = re.sub(r"\{\{[^}]*\}\}|`[^`]*`", "", MARKDOWN.split("## References")[0])
    md = "\n".join(line for line in md.splitlines() if not line.startswith("    "))
    assert _typed_results(md, "%") == []
    tex = re.sub(r"(?<!\\)%.*", "", TEX).split(r"\begin{thebibliography}")[0]
    tex = re.sub(r"\\result\{[^}]*\}|\\texttt\{[^}]*\}|\$[^$]*\$", "", tex)
    tex = re.sub(r"\\begin\{equation\}.*?\\end\{equation\}", "", tex, flags=re.S)
    assert _typed_results(tex, r"\\,\\%") == []


def test_a_subset_without_a_scored_flight_still_renders():
    """A configured subset none of whose flights was scored (a small corpus, or all of
    them left out) quotes "none" and "n/a" rather than stopping the paper."""
    n = paper_numbers(comparison(), sweep(), leakage(), methods=("a", "b"),
                      subsets=("no_emr", "all"))
    assert (n["best:no_emr"], n["bestaccuracy:no_emr"], n["tied:no_emr"]) == ("none", "n/a",
                                                                              "none")
    assert n["flights:no_emr"] == "n/a" and n["best:all"] == "b"
