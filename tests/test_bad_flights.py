"""A bad flight never stops a stage and never moves another flight unnoticed: every entry
of processed/ is accounted for, the injected grid and the recordings pass over what a
flight cannot give, one absurd flight cannot move a threshold far, and the records say
what calibrated them."""

import os

import numpy as np
import pytest
from broken import IMU, ROLL, edit, set_cell
from recordings import content

from alfa_bench.analysis import detect_all
from alfa_bench.data import AlfaDataError, load_flight, scan_flights
from alfa_bench.data.inject import InjectedGrid
from alfa_bench.data.manifest import manifest_of, manifest_row
from alfa_bench.data.signals import check_signals
from alfa_bench.data.synthetic import write_flight
from alfa_bench.methods import make_detector, run_detector
from alfa_bench.methods.extremes import CAP_LEVEL, gumbel_threshold
from alfa_bench.outputs.rerun_log import write_rerun_log

FREE = "carbonZ_2018-07-18-16-37-39_1_no_failure"
ENGINE = "carbonZ_2018-07-18-15-53-31_1_engine_failure"


def test_every_entry_of_processed_is_a_flight_or_a_failure_saying_why(tmp_path):
    processed = tmp_path / "processed"
    write_flight(processed, ENGINE, onset_s=50.0)
    os.symlink(tmp_path / "gone", processed / "carbonZ_2018-07-18-16-22-01_engine_failure")
    (processed / "notes.txt").write_text("not a flight\n")
    (processed / "empty_folder").mkdir()
    write_flight(processed, "my_flight", onset_s=50.0)
    (processed / ".hidden").mkdir()
    manifest, failures = scan_flights(processed)
    assert list(manifest["flight"]) == [ENGINE]
    why = dict(zip(failures["flight"], failures["error"], strict=True))
    assert set(why) == {"carbonZ_2018-07-18-16-22-01_engine_failure", "notes.txt",
                        "empty_folder", "my_flight"}
    assert "a broken link" in why["carbonZ_2018-07-18-16-22-01_engine_failure"]
    assert "a file" in why["notes.txt"]
    assert "no empty_folder-<topic>.csv files" in why["empty_folder"]
    assert "not an ALFA flight name" in why["my_flight"]
    # the broken link still counts in the subsets its name puts it in
    assert failures.set_index("flight").at[
        "carbonZ_2018-07-18-16-22-01_engine_failure", "subsets"] != ""


def test_a_bad_cell_in_a_fault_free_flight_skips_its_sensor_in_the_grid(tmp_path):
    """The loader refuses such a flight (check_signals); a grid built from one that did
    not come through it skips the sensor, saying why."""
    folder = write_flight(tmp_path / "processed", FREE, seed=1)
    manifest = manifest_of([manifest_row(load_flight(folder))])
    edit(ROLL, lambda ls: ls[:7] + [set_cell(ls[7], 5, "nan")] + ls[8:])(folder)
    flight = load_flight(folder)
    with pytest.raises(AlfaDataError, match="empty or NaN cell"):
        check_signals(flight)
    grid = InjectedGrid({FREE: flight}, manifest, tmp_path / "grid", ["roll", "pitch_rate"],
                        [{"kind": "stuck", "magnitude": 0.0}], [0.5])
    assert [s["sensor"] for s in grid.skipped] == ["roll"]
    assert "empty or NaN cell" in grid.skipped[0]["reason"]
    assert len(grid) == 1 and all(grid[name] is not None for name in grid)


def test_a_recording_leaves_out_a_signal_the_flight_cannot_give(tmp_path, caplog):
    folder = write_flight(tmp_path / "processed", ENGINE, onset_s=50.0)
    edit(IMU, lambda ls: [",".join(c for i, c in enumerate(line.split(",")) if i != 4)
                          for line in ls])(folder)       # no angular_velocity.x column
    flight = load_flight(folder)
    detector = make_detector("rls_arx_zscore", {"pairs": [
        {"name": "roll", "input": "roll_cmd", "output": "roll"}]})
    path = tmp_path / f"{flight.id}.rrd"
    write_rerun_log(flight, {"rls": run_detector(detector, flight, probes=True)},
                    ["roll_cmd", "roll", "roll_rate"], path, {"inputs": {}})
    entities = {entity for entity, _, _ in content(path)}
    assert "/signals/attitude/roll" in entities and "/signals/rates/roll_rate" not in entities
    assert "signal roll_rate not recorded" in caplog.text


def test_one_absurd_flight_moves_a_threshold_no_further_than_a_stated_bound():
    """However absurd the one extra maximum, the threshold is the same, and it moves
    by less than the cap's distance from the median maximum (the bound)."""
    rng = np.random.default_rng(3)
    maxima = rng.gumbel(2.0, 0.5, size=20)
    level = 1 - 0.1 / 5
    clean = gumbel_threshold(maxima, level)
    q1, q2, q3 = np.quantile(maxima, [0.25, 0.5, 0.75])
    g = lambda p: -np.log(-np.log(p))  # noqa: E731
    bound = (q3 - q1) * (g(CAP_LEVEL) - g(0.5)) / (g(0.75) - g(0.25))
    moved = [gumbel_threshold(np.r_[maxima, absurd], level) for absurd in (1e3, 1e6, 1e12)]
    assert moved[0] == pytest.approx(moved[1]) == pytest.approx(moved[2])
    assert 0 < moved[0] - clean < bound
    # maximum likelihood alone would follow it without bound
    from scipy import stats
    assert stats.gumbel_r.ppf(level, *stats.gumbel_r.fit(np.r_[maxima, 1e6])) > 1e5


def test_a_record_lists_the_segments_that_calibrated_it(corpus_flights, corpus_manifest):
    spec = {"detector": "glrt_residuals", "params": {}}
    for record, _ in detect_all("glrt_arx", spec, corpus_flights, corpus_manifest,
                                {"group_by": "date", "margin_s": 1.0}):
        cal = record["calibration"]
        assert set(cal["segments"]) == set(cal["flights"])
        for flight, spans in cal["segments"].items():
            onset = corpus_flights[flight].fault.onset_s
            for start, stop in spans:
                assert 0 <= start < stop and (onset is None or stop < onset - 1.0)
        assert set(record["provenance"]["inputs"]["calibration_sha256"]) == set(cal["flights"])



def test_a_signal_no_catalogue_holds_stops_the_run_not_one_flight(corpus_flights,
                                                                  corpus_manifest):
    from alfa_bench.data import UnknownSignalError
    spec = {"detector": "rls_arx_zscore",
            "params": {"pairs": [{"name": "roll", "input": "roll_cmdd", "output": "roll"}]}}
    failures = []
    with pytest.raises(UnknownSignalError, match="roll_cmdd"):
        list(detect_all("typo", spec, corpus_flights, corpus_manifest,
                        {"group_by": "date", "margin_s": 1.0}, failures))
    assert failures == []
