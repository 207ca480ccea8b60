"""The manifest over a synthetic corpus: rows, subsets, schema, round trip."""

import pytest

from alfa_bench.data import AlfaDataError, build_manifest, read_manifest, subset_flights
from alfa_bench.data.manifest import validate_manifest


@pytest.fixture(scope="module")
def manifest(corpus):
    return build_manifest(corpus)


def test_one_row_per_flight_found(manifest, corpus):
    assert sorted(manifest["flight"]) == sorted(p.name for p in corpus.iterdir())


def test_subsets_follow_the_rules(manifest):
    icra = set(subset_flights(manifest, "icra22"))
    assert icra == {
        "carbonZ_2018-07-18-15-53-31_1_engine_failure",
        "carbonZ_2018-07-18-16-37-39_1_no_failure",
        "carbonZ_2018-09-11-15-06-34_3_rudder_left_failure",
    }  # emr and October flights are out
    assert len(subset_flights(manifest, "all")) == 6
    assert subset_flights(manifest, "emr") == [
        "carbonZ_2018-07-30-16-29-45_engine_failure_with_emr_traj"]


def test_fault_columns(manifest):
    row = manifest.set_index("flight").loc["carbonZ_2018-09-11-15-06-34_3_rudder_left_failure"]
    assert row["fault_class"] == "rudder"
    assert row["onset_s"] == pytest.approx(45.0)
    assert row["pre_fault_s"] == row["onset_s"]
    assert row["fault_s"] == pytest.approx(row["fault_end_s"] - row["onset_s"])
    free = manifest.set_index("flight").loc["carbonZ_2018-07-18-16-37-39_1_no_failure"]
    assert free["fault_class"] == "none" and free["pre_fault_s"] == free["flight_s"]


def test_round_trip_through_csv(manifest, tmp_path):
    path = tmp_path / "flights.csv"
    manifest.to_csv(path, index=False)
    back = read_manifest(path)
    assert back["flight"].tolist() == manifest["flight"].tolist()
    assert back["ground_truth"].dtype == bool
    assert back["onset_s"].isna().sum() == manifest["onset_s"].isna().sum()


def test_schema_rejects_a_bad_row(manifest):
    bad = manifest.copy()
    bad.loc[0, "fault_class"] = "propeller"
    with pytest.raises(AlfaDataError, match="fault_class"):
        validate_manifest(bad)


def test_checksum_changes_with_content(corpus, tmp_path):
    import shutil
    copy = tmp_path / "processed"
    shutil.copytree(corpus, copy)
    before = build_manifest(copy).set_index("flight")["sha256"]
    f = next(copy.glob("*engine_failure/*roll.csv"))
    f.write_text(f.read_text().replace(",NED,", ",ned,", 1))
    after = build_manifest(copy).set_index("flight")["sha256"]
    assert (before != after).sum() == 1
