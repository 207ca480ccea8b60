"""A public ALFA study's published results, quoted beside the reproduction of its
method (never computed, never used for fitting).

The study ``bvsrasen/alfa-fault-detection`` (GitHub), ``docs/sonuclar.md``, table
"Lojistik regresyon: uçuş uçuş": per labelled flight, the onset and the first alarm on
its own clock (seconds from the flight's first ``nav_info-roll`` row) and the outcome
by the paper's per-flight rule, one per flight: an alarm before onset (or on a
fault-free flight) a false positive, a later one a detection however late, none a
miss or a true negative. Its 46 labelled flights, of 30 recordings, each scored by a
model that left the flight's recording out.
"""

import math

import pandas as pd

from alfa_bench.data import subset_flights
from alfa_bench.render import fmt, markdown

from .per_flight import subset_counts
from .scoring import flight_outcome

__all__ = ["STUDY_FLIGHTS", "STUDY_NAME", "STUDY_SUMMARY", "against_study",
           "against_study_markdown", "protocol_steps", "protocol_steps_markdown",
           "study_counts", "study_outcome"]

STUDY_NAME = "bvsrasen/alfa-fault-detection, logistic regression (published)"

#: its summary row: flights and outcomes by the paper's rule, one per flight
STUDY_SUMMARY = {"flights": 46, "tp": 24, "fp": 6, "fn": 7, "tn": 9}

#: (flight, onset s or None, first alarm s or None, outcome), as published
STUDY_FLIGHTS = (
    ("carbonZ_2018-07-18-15-53-31_1_engine_failure", 116.26, 119.7, "TP"),
    ("carbonZ_2018-07-18-15-53-31_2_engine_failure", 73.41, 75.5, "TP"),
    ("carbonZ_2018-07-18-16-22-01_engine_failure_with_emr_traj", 116.63, 51.1, "FP"),
    ("carbonZ_2018-07-18-16-37-39_1_no_failure", None, None, "TN"),
    ("carbonZ_2018-07-18-16-37-39_2_engine_failure_with_emr_traj", 114.06, 114.6, "TP"),
    ("carbonZ_2018-07-30-16-29-45_engine_failure_with_emr_traj", 123.15, None, "FN"),
    ("carbonZ_2018-07-30-16-39-00_1_engine_failure", 116.79, 118.7, "TP"),
    ("carbonZ_2018-07-30-16-39-00_2_engine_failure", 91.57, 72.6, "FP"),
    ("carbonZ_2018-07-30-16-39-00_3_no_failure", None, None, "TN"),
    ("carbonZ_2018-07-30-17-10-45_engine_failure_with_emr_traj", 117.17, 36.4, "FP"),
    ("carbonZ_2018-07-30-17-20-01_engine_failure_with_emr_traj", 87.61, 88.3, "TP"),
    ("carbonZ_2018-07-30-17-36-35_engine_failure_with_emr_traj", 133.43, 135.5, "TP"),
    ("carbonZ_2018-07-30-17-46-31_engine_failure_with_emr_traj", 90.36, 92.5, "TP"),
    ("carbonZ_2018-09-11-11-56-30_engine_failure", 103.57, 105.5, "TP"),
    ("carbonZ_2018-09-11-14-16-55_no_failure", None, None, "TN"),
    ("carbonZ_2018-09-11-14-22-07_1_engine_failure", 104.85, 105.4, "TP"),
    ("carbonZ_2018-09-11-14-22-07_2_engine_failure", 49.86, 15.0, "FP"),
    ("carbonZ_2018-09-11-14-41-38_no_failure", None, None, "TN"),
    ("carbonZ_2018-09-11-14-41-51_elevator_failure", 117.83, 119.8, "TP"),
    ("carbonZ_2018-09-11-14-52-54_left_aileron__right_aileron__failure", 105.25, 17.2, "FP"),
    ("carbonZ_2018-09-11-15-05-11_1_elevator_failure", 63.48, 72.9, "TP"),
    ("carbonZ_2018-09-11-15-05-11_2_no_failure", None, 58.8, "FP"),
    ("carbonZ_2018-09-11-15-06-34_1_rudder_right_failure", 55.52, 58.2, "TP"),
    ("carbonZ_2018-09-11-15-06-34_2_rudder_right_failure", 51.97, 53.6, "TP"),
    ("carbonZ_2018-09-11-15-06-34_3_rudder_left_failure", 60.02, 60.7, "TP"),
    ("carbonZ_2018-09-11-17-27-13_1_rudder_zero__left_aileron_failure", 116.32, None, "FN"),
    ("carbonZ_2018-09-11-17-27-13_2_both_ailerons_failure", 65.77, 78.7, "TP"),
    ("carbonZ_2018-09-11-17-55-30_1_right_aileron_failure", 111.92, None, "FN"),
    ("carbonZ_2018-09-11-17-55-30_2_left_aileron_failure", 49.98, None, "FN"),
    ("carbonZ_2018-10-05-14-34-20_1_no_failure", None, None, "TN"),
    ("carbonZ_2018-10-05-14-34-20_2_right_aileron_failure_with_emr_traj", 152.2, None, "FN"),
    ("carbonZ_2018-10-05-14-37-22_1_no_failure", None, None, "TN"),
    ("carbonZ_2018-10-05-14-37-22_2_right_aileron_failure", 73.38, None, "FN"),
    ("carbonZ_2018-10-05-14-37-22_3_left_aileron_failure", 72.4, None, "FN"),
    ("carbonZ_2018-10-05-15-52-12_1_no_failure", None, None, "TN"),
    ("carbonZ_2018-10-05-15-52-12_2_no_failure", None, None, "TN"),
    ("carbonZ_2018-10-05-15-52-12_3_engine_failure_with_emr_traj", 49.13, 51.4, "TP"),
    ("carbonZ_2018-10-05-15-55-10_engine_failure_with_emr_traj", 100.11, 101.8, "TP"),
    ("carbonZ_2018-10-05-16-04-46_engine_failure_with_emr_traj", 76.19, 77.0, "TP"),
    ("carbonZ_2018-10-18-11-03-57_engine_failure_with_emr_traj", 104.25, 108.0, "TP"),
    ("carbonZ_2018-10-18-11-04-00_engine_failure_with_emr_traj", 111.16, 111.7, "TP"),
    ("carbonZ_2018-10-18-11-04-08_1_engine_failure_with_emr_traj", 100.36, 101.0, "TP"),
    ("carbonZ_2018-10-18-11-04-08_2_engine_failure_with_emr_traj", 98.22, 101.1, "TP"),
    ("carbonZ_2018-10-18-11-04-35_engine_failure_with_emr_traj", 101.3, 102.6, "TP"),
    ("carbonZ_2018-10-18-11-06-06_engine_failure_with_emr_traj", 102.52, 104.8, "TP"),
    ("carbonZ_2018-10-18-11-08-24_no_failure", None, None, "TN"),
)


def _missing(v) -> bool:
    return v is None or (isinstance(v, float) and math.isnan(v))


def study_outcome(onset_s: float | None, first_alarm_s: float | None) -> str:
    """A flight's one outcome by the paper's rule, as the study counts it: ``FP`` for an
    alarm before onset or on a fault-free flight, ``TP`` for a later one however late,
    ``FN`` or ``TN`` for none (:func:`~.scoring.flight_outcome` without a deadline, an
    early alarm on a faulty flight counted once, as ``FP``). NaN is as None."""
    outcome = flight_outcome(None if _missing(onset_s) else onset_s,
                             None if _missing(first_alarm_s) else first_alarm_s)
    return "FP" if outcome == "FP+FN" else outcome


def study_counts(outcomes) -> dict[str, int]:
    """``tp``, ``fp``, ``fn``, ``tn`` of :func:`study_outcome` values."""
    outcomes = list(outcomes)
    return {k.lower(): outcomes.count(k) for k in ("TP", "FP", "FN", "TN")}


def _why(row: dict) -> str:
    """What the run's margins say of a flight whose outcome differs from the study's."""
    if row["outcome"] == "FP":
        return (f"largest score before onset {fmt(row['margin_before'])} x its fold's "
                "threshold")
    if row["outcome"] == "TP":
        return (f"detected {fmt(row['delay_s'])} s after onset; largest score before onset "
                f"{fmt(row['margin_before'])} x its fold's threshold")
    return (f"no alarm; largest score from onset to the deadline "
            f"{fmt(row['margin_in_time'])} x its fold's threshold")


def against_study(per_flight: pd.DataFrame, run: str) -> pd.DataFrame:
    """Flight by flight, the study's published outcome and first alarm beside ``run``'s
    (rows of a per-flight table, :func:`~.per_flight.per_flight_table`), for the flights
    both scored; ``why`` reads the run's margins where the outcomes differ."""
    ours = per_flight[per_flight["method"] == run].set_index("flight")
    rows = []
    for flight, onset, alarm, outcome in STUDY_FLIGHTS:
        if flight not in ours.index:
            continue
        r = ours.loc[flight]
        mine = {"outcome": study_outcome(r["onset_s"], r["first_alarm_s"]),
                "delay_s": r["delay_s"], "margin_before": r["margin_before"],
                "margin_in_time": r["margin_in_time"]}
        rows.append({"flight": flight, "study_outcome": outcome, "study_alarm_s": alarm,
                     "study_delay_s": None if _missing(alarm) or onset is None
                     else alarm - onset,
                     "outcome": mine["outcome"], "first_alarm_s": r["first_alarm_s"],
                     "delay_s": r["delay_s"], "same": mine["outcome"] == outcome,
                     "why": "" if mine["outcome"] == outcome else _why(mine)})
    return pd.DataFrame(rows, columns=["flight", "study_outcome", "study_alarm_s",
                                       "study_delay_s", "outcome", "first_alarm_s",
                                       "delay_s", "same", "why"])


def against_study_markdown(table: pd.DataFrame, run: str) -> str:
    """The counts on the flights both scored, then the flights whose outcome differs."""
    if table.empty:
        return ""
    ours, theirs = study_counts(table["outcome"]), study_counts(table["study_outcome"])
    counts = [[who, str(len(table)), *(str(c[k]) for k in ("tp", "fp", "fn", "tn"))]
              for who, c in ((f"`{run}`", ours), ("the study, published", theirs))]
    counts.append(["the study, published, all its flights", str(STUDY_SUMMARY["flights"]),
                   *(str(STUDY_SUMMARY[k]) for k in ("tp", "fp", "fn", "tn"))])
    differ = table[~table["same"]]
    rows = [[f"`{r['flight']}`", r["study_outcome"], fmt(r["study_alarm_s"]), r["outcome"],
             fmt(r["first_alarm_s"]), r["why"]] for r in differ.to_dict(orient="records")]
    head = ("The study's per-flight rule (the paper's, one outcome a flight: an alarm "
            "before onset a false positive, a later one a detection however late), on "
            f"the flights both scored; {int(table['same'].sum())} of {len(table)} have "
            "the study's outcome.\n\n")
    return head + markdown([
        (f"`{run}` against {STUDY_NAME}", ["run", "flights", "TP", "FP", "FN", "TN"], counts),
        ("Flights whose outcome differs from the study's",
         ["flight", "study", "study's alarm, s", "ours", "our alarm, s", "why"], rows)])


def protocol_steps(per_flight: pd.DataFrame, manifest: pd.DataFrame, steps: list[dict],
                   primary: str, stable: float) -> pd.DataFrame:
    """Per step (``{"run", "change"}``, in order) of a protocol walk: on the ``primary``
    subset within the per-flight table's deadline, the faults detected in time, the
    faulty flights alarmed before onset, the fault-free flights alarmed and the stable
    detections (survival >= ``stable``, where the run has pools); and the study's
    one-outcome counts on every flight it scored."""
    members = set(subset_flights(manifest, primary))
    rows = []
    for i, step in enumerate(steps):
        runs = per_flight[per_flight["method"] == step["run"]]
        if runs.empty:
            continue
        counts = study_counts(study_outcome(o, a) for o, a in
                              zip(runs["onset_s"], runs["first_alarm_s"], strict=True))
        rows.append({"step": i, "run": step["run"], "change": step["change"],
                     **subset_counts(runs, members, stable), "flights": len(runs),
                     **{f"{k}_study_rule": v for k, v in counts.items()}})
    return pd.DataFrame(rows)


def protocol_steps_markdown(table: pd.DataFrame, primary: str, deadline_s: float) -> str:
    """:func:`protocol_steps` as one Markdown table, with what its columns count."""
    if table.empty:
        return "None of the protocol steps' runs was scored.\n"
    rows = [[str(r["step"]), f"`{r['run']}`", r["change"],
             f"{r['detected']} of {r['faulty_flights']}", str(r["early_alarms"]),
             f"{r['fault_free_alarmed']} of {r['fault_free_flights']}",
             "-" if pd.isna(r["stable_detections"]) else str(int(r["stable_detections"])),
             " / ".join(str(r[f"{k}_study_rule"]) for k in ("tp", "fp", "fn", "tn"))]
            for r in table.to_dict(orient="records")]
    head = (f"From the public study's protocol to this project's, one change a step. On "
            f"`{primary}`, within {deadline_s:g} s of onset: faults detected in time, "
            "faulty flights alarmed before onset, fault-free flights alarmed, and "
            "detections stable when the calibration flights are resampled (`-`: no "
            "pools). Last, the study's rule on every labelled flight: one outcome a "
            "flight, an alarm before onset a false positive, a later one a detection "
            "however late.\n\n")
    return head + markdown([(
        "Where the public study's result comes from",
        ["step", "run", "change", "detected in time", "early alarms", "fault-free alarmed",
         "stable", "study's rule: TP / FP / FN / TN"], rows)])
