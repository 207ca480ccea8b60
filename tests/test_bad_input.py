"""Details of bad-input handling beyond the corpus of tests/test_broken_corpus.py:
more malformed rows, and what exactly a repair keeps."""

import pytest

from alfa_bench.data import AlfaDataError, load_flight, sample

ROLL = "mavros-nav_info-roll"


def roll_file(folder):
    return folder / f"{folder.name}-{ROLL}.csv"


def edit_lines(path, fn):
    lines = path.read_text().splitlines()
    path.write_text("\n".join(fn(lines)) + "\n")


def set_cell(line: str, column: int, value: str) -> str:
    cells = line.split(",")
    cells[column] = value
    return ",".join(cells)


def read_roll(folder):
    """Load the flight and read the roll columns a detector would use."""
    f = load_flight(folder)
    return sample(f, ["roll_cmd", "roll"], 25.0)


@pytest.mark.parametrize("corrupt, message, column, line", [
    (lambda p: edit_lines(p, lambda ls: ls[:7] + [set_cell(ls[7], 4, "")] + ls[8:]),
     "empty or NaN cell", "field.commanded", 8),
    (lambda p: edit_lines(p, lambda ls: ls[:3] + [ls[3].rsplit(",", 1)[0]] + ls[4:]),
     "row has 5 fields, header has 6", None, 4),
    (lambda p: edit_lines(p, lambda ls: ls[:3] + [set_cell(ls[3], 0, "12.5e17")] + ls[4:]),
     "not an integer number of ns", "%time", 4),
])
def test_bad_cell_or_file_is_a_named_error(one_flight, corrupt, message, column, line):
    corrupt(roll_file(one_flight))
    with pytest.raises(AlfaDataError) as err:
        read_roll(one_flight)
    e = err.value
    assert message in str(e)
    assert e.flight == one_flight.name
    assert e.file == roll_file(one_flight).name
    assert e.column == column
    assert e.line == line


def test_truncated_last_line_is_dropped_and_logged(one_flight, caplog):
    path = roll_file(one_flight)
    full = path.read_text()
    n_rows = full.count("\n") - 1
    path.write_text(full[:-7])  # cut inside the last row, as an interrupted copy does
    f = load_flight(one_flight)
    assert f.topic(ROLL).t.size == n_rows - 1
    assert any("truncated last line" in r for r in f.repairs)
    assert "truncated last line" in caplog.text


def test_duplicate_timestamps_keep_the_last_row_and_are_logged(one_flight, caplog):
    path = roll_file(one_flight)
    lines = path.read_text().splitlines()
    dup = set_cell(lines[10], 5, "99.0")
    edit_lines(path, lambda ls: ls[:11] + [set_cell(dup, 0, ls[10].split(",")[0])] + ls[11:])
    f = load_flight(one_flight)
    roll = f.topic(ROLL)
    assert roll.t.size == len(lines) - 1
    assert roll.values("field.measured")[9] == 99.0
    assert any("repeating the previous row's %time" in r for r in f.repairs)
    assert "repeating" in caplog.text


def test_unused_column_may_be_bad(one_flight):
    """Only what is used must be numeric: a bad frame_id harms nothing."""
    edit_lines(roll_file(one_flight), lambda ls: ls[:4] + [set_cell(ls[4], 3, "??")] + ls[5:])
    assert read_roll(one_flight).x.shape[1] == 2
