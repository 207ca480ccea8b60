"""Each kind of bad input: a clear error naming flight, file, column and line,
or a documented repair that is logged and recorded on the flight."""

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
    (lambda p: p.write_text(""), "empty file", None, None),
    (lambda p: p.write_text(p.read_text().splitlines()[0] + "\n"), "header only", None, None),
    (lambda p: edit_lines(p, lambda ls: ls[:5] + [set_cell(ls[5], 5, "abc")] + ls[6:]),
     "non-numeric cell 'abc'", "field.measured", 6),
    (lambda p: edit_lines(p, lambda ls: ls[:7] + [set_cell(ls[7], 4, "nan")] + ls[8:]),
     "empty or NaN cell", "field.commanded", 8),
    (lambda p: edit_lines(p, lambda ls: ls[:7] + [set_cell(ls[7], 4, "")] + ls[8:]),
     "empty or NaN cell", "field.commanded", 8),
    (lambda p: edit_lines(p, lambda ls: ls[:9] + [set_cell(ls[9], 5, "inf")] + ls[10:]),
     "infinite value", "field.measured", 10),
    (lambda p: edit_lines(p, lambda ls: ls[:3] + [ls[4], ls[3]] + ls[5:]),
     "timestamps go backwards", "%time", 5),
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


def test_failure_status_without_rows_is_an_error(one_flight):
    gt = one_flight / f"{one_flight.name}-failure_status-engines.csv"
    gt.write_text("%time,field.data\n")
    with pytest.raises(AlfaDataError, match="header only") as err:
        load_flight(one_flight)
    assert err.value.file == gt.name


def test_unknown_ground_truth_topic_is_an_error(one_flight):
    gt = one_flight / f"{one_flight.name}-failure_status-engines.csv"
    gt.rename(one_flight / f"{one_flight.name}-failure_status-propeller.csv")
    with pytest.raises(AlfaDataError, match="unknown ground-truth topic"):
        load_flight(one_flight)


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
