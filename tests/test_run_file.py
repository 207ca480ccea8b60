"""The run's provenance file: every output's checksum, and tables read against it."""

import json

import pytest

from alfa_bench.outputs.provenance import read_provenance, run_id, stamp, write_run_file


def test_tables_are_read_against_the_checksum_of_their_run(tmp_path):
    prov = {"code": {"git_commit": "abc"}, "packages": {}, "config": {"a": 1},
            "inputs": {"flight_sha256": {"f": "0" * 64}}}
    tables = tmp_path / "results/tables"
    tables.mkdir(parents=True)
    (tables / "t.csv").write_text("a,b\n1,2\n")
    (tables / "t.md").write_text("| a |\n|---|\n| 1 |\n")
    stamp(tables / "t.csv", prov)
    stamp(tables / "t.md", prov)
    (tmp_path / "results/runtime").mkdir()
    (tmp_path / "results/runtime/r.csv").write_text("s\n0.1\n")
    write_run_file(tmp_path / "results/provenance.json", prov,
                   [tables, tmp_path / "results/runtime"], root=tmp_path,
                   unchecked=["results/runtime/*"])
    run = json.loads((tmp_path / "results/provenance.json").read_text())
    assert (tables / "t.csv").read_text() == "a,b\n1,2\n"          # the CSV stays plain
    assert f"Run `{run_id(prov)}`" in (tables / "t.md").read_text().splitlines()[-1]
    assert run["run_id"] == run_id(prov) and run["outputs"]["results/runtime/r.csv"] is None
    assert read_provenance(tables / "t.csv") == prov
    assert read_provenance(tmp_path / "results/runtime/r.csv") == prov
    (tables / "t.csv").write_text("a,b\n1,3\n")
    with pytest.raises(ValueError, match="no longer"):
        read_provenance(tables / "t.csv")
    (tables / "new.csv").write_text("a\n")
    with pytest.raises(ValueError, match="not among"):
        read_provenance(tables / "new.csv")
    # the same code, packages and config name the same run, whatever flights it read
    assert run_id({**prov, "inputs": {}}) == run_id(prov)
    assert run_id({**prov, "config": {"a": 2}}) != run_id(prov)
