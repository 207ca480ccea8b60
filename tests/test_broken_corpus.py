"""The broken-flight corpus (tests/broken.py): each kind of bad input ends as documented,
and random corruptions of a valid flight never give an unexplained result."""

import shutil

import numpy as np
import pytest
from broken import CASES, NAME, outcome
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from alfa_bench.data import AlfaDataError
from alfa_bench.data.synthetic import write_flight


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    """The valid flight every case corrupts a copy of, and its result."""
    folder = write_flight(tmp_path_factory.mktemp("clean") / "processed", NAME, onset_s=50.0)
    kind, (flight, trace) = outcome(folder)
    assert kind == "ok" and not flight.repairs
    return folder, trace


def copy_of(folder, dest):
    target = dest / "processed" / folder.name
    shutil.copytree(folder, target)
    return target


def same_trace(a, b) -> bool:
    return (np.array_equal(a.t, b.t) and np.array_equal(a.score, b.score, equal_nan=True)
            and np.array_equal(a.alarm, b.alarm))


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_each_broken_flight_ends_as_documented(case, clean, tmp_path, caplog):
    folder = case.corrupt(copy_of(clean[0], tmp_path))
    kind, result = outcome(folder)
    expect = case.expect
    assert kind == ("ok" if expect.kind in ("repair", "warning") else expect.kind)
    if kind == "error":
        assert expect.message in str(result)
        assert result.flight == folder.name and folder.name in str(result)
        assert result.file == (f"{folder.name}-{expect.file}.csv" if expect.file else None)
        if expect.column is not None:
            assert result.column == expect.column
        if expect.line is not None:
            assert result.line == expect.line
    elif expect.kind == "repair":
        flight, _ = result
        assert any(expect.message in r for r in flight.repairs)
        assert expect.message in caplog.text and folder.name in caplog.text
    elif expect.kind == "ok":
        assert same_trace(result[1], clean[1])
    else:   # warning, excluded, skipped: said in the log
        assert expect.message in caplog.text
        if expect.kind == "warning":
            assert same_trace(result[1], clean[1])


# ---- random corruptions -------------------------------------------------------------

JUNK = ["", "nan", "NaN", "inf", "-inf", "abc", "1e400", "0x10", " ", "1,2", '"x"']


def corruption():
    """(file index, operation, position, junk) drawn at random."""
    return st.tuples(st.integers(0, 10**6),
                     st.sampled_from(["truncate", "delete_file", "empty", "duplicate_line",
                                      "swap_lines", "junk_cell", "junk_line", "drop_field",
                                      "header_only"]),
                     st.integers(0, 10**9), st.sampled_from(JUNK))


def apply(folder, draw) -> str:
    files = sorted(folder.glob("*.csv"))
    index, op, pos, junk = draw
    path = files[index % len(files)]
    text = path.read_text()
    lines = text.splitlines()
    if len(lines) < 2:               # emptied by an earlier draw
        return "nothing"
    i = 1 + pos % (len(lines) - 1)                       # a data line
    if op == "truncate":
        # inside a line: a cut at a line end leaves a valid, shorter file
        cuts = [k for k in range(1, len(text)) if text[k - 1] != "\n"]
        path.write_text(text[:cuts[pos % len(cuts)]])
    elif op == "delete_file":
        path.unlink()
    elif op == "empty":
        path.write_text("")
    elif op == "header_only":
        path.write_text(lines[0] + "\n")
    elif op == "duplicate_line":
        path.write_text("\n".join(lines[:i + 1] + lines[i:]) + "\n")
    elif op == "swap_lines":
        j = i + 1 if i + 1 < len(lines) else i - 1
        if j < 1 or lines[i].split(",")[0] == lines[j].split(",")[0]:
            return "nothing"
        lines[i], lines[j] = lines[j], lines[i]
        path.write_text("\n".join(lines) + "\n")
    elif op == "junk_cell":
        cells = lines[i].split(",")
        cells[pos % len(cells)] = junk
        lines[i] = ",".join(cells)
        path.write_text("\n".join(lines) + "\n")
    elif op == "junk_line":
        path.write_text("\n".join(lines[:i] + [junk] + lines[i:]) + "\n")
    elif op == "drop_field":
        lines[i] = lines[i].rsplit(",", 1)[0]
        path.write_text("\n".join(lines) + "\n")
    return f"{op} {path.name}"


@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(draws=st.lists(corruption(), min_size=1, max_size=3))
@pytest.mark.slow
def test_random_corruptions_never_give_an_unexplained_result(draws, clean, tmp_path_factory,
                                                              caplog):
    """Every run ends in a named error, a logged exclusion, a logged repair, or exactly
    the clean flight's result (a corruption of data no detector reads); never in any
    other exception, and never in a different result with nothing said."""
    caplog.clear()
    folder = copy_of(clean[0], tmp_path_factory.mktemp("corrupt"))
    done = [apply(folder, d) for d in draws]
    kind, result = outcome(folder)
    if kind == "error":
        assert isinstance(result, AlfaDataError)
        assert result.flight == folder.name, done
        if result.file:
            assert result.file.startswith(folder.name + "-"), done
    elif kind == "excluded":
        assert "kept out of labelled scoring" in caplog.text, done
    else:
        assert kind == "ok", done
        flight, trace = result
        if flight.repairs:
            assert all(r in caplog.text for r in flight.repairs), done
        else:
            assert same_trace(trace, clean[1]), done
