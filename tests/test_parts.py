"""A run's part of a table, written and read back for the merge (outputs/parts.py)."""

import math

import pandas as pd

from alfa_bench.outputs.parts import read_part_rows, read_parts, write_part, write_part_rows


def test_csv_parts_stack_back_to_the_table_of_every_run(tmp_path):
    """Strings a reader could take for missing ("none", "NA") stay strings, an empty
    cell is NaN as written, a part with no rows adds none: the stack writes the bytes
    the table of every run at once writes."""
    rows = [{"method": "a", "kind": "none", "label": "NA", "n": 3, "rate": 0.1 + 0.2,
             "mean": math.nan, "ok": True},
            {"method": "b", "kind": "drift", "label": "x,y", "n": 4, "rate": 1e-300,
             "mean": 2.5, "ok": False}]
    whole = pd.DataFrame(rows)
    paths = [tmp_path / f"{m}.csv" for m in ("a", "empty", "b")]
    write_part(pd.DataFrame(rows[:1]), paths[0])
    write_part(pd.DataFrame(columns=whole.columns), paths[1])
    write_part(pd.DataFrame(rows[1:]), paths[2])
    merged = read_parts(paths)
    assert merged.to_csv(index=False) == whole.to_csv(index=False)
    assert list(read_parts(paths[1:2]).columns) == list(whole.columns)


def test_row_parts_keep_each_value_and_the_key_order(tmp_path):
    """An empty string and a missing value stay apart, NaN stays a float, and the keys
    keep their order (the merged table's columns)."""
    rows = [{"z": "", "a": None, "m": math.nan, "b": True}, {"z": "x", "a": 1, "m": 0.5,
                                                            "b": False}]
    write_part_rows(rows[:1], tmp_path / "a.jsonl")
    write_part_rows(rows[1:], tmp_path / "b.jsonl")
    back = read_part_rows([tmp_path / "a.jsonl", tmp_path / "b.jsonl"])
    assert [list(r) for r in back] == [["z", "a", "m", "b"]] * 2
    assert back[0]["z"] == "" and back[0]["a"] is None and math.isnan(back[0]["m"])
    assert back[1] == rows[1]
    assert pd.DataFrame(back).to_csv(index=False) == pd.DataFrame(rows).to_csv(index=False)
