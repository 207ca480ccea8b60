"""The README is short, starts with the two commands, quotes no result by hand, and
every file it or the docs link to is there."""

import re
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DOCS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]


def test_the_readme_is_short_and_opens_with_the_two_commands():
    text = (REPO / "README.md").read_text()
    assert len(text.splitlines()) <= 120
    block = re.search(r"```bash\n(.*?)```", text, re.S).group(1)
    commands = [line for line in block.splitlines() if line and not line.startswith("#")]
    install = 'python3 -m venv .venv && .venv/bin/pip install -q -c constraints.txt -e ".[test]"'
    assert commands == [f"{install} && .venv/bin/snakemake all --cores 2",
                        f"{install} && .venv/bin/python -m pytest"]


def test_the_readme_quotes_no_result_by_hand():
    """Rates, counts of flights and run times come from the run (paper/build/paper.md
    and results/), never typed into the README."""
    text = (REPO / "README.md").read_text()
    typed = re.findall(r"\d+(?:\.\d+)? ?%|\b\d+ (?:of|flights|faults|s\b|min)", text)
    assert not typed, typed


def test_every_local_link_resolves():
    missing = []
    for doc in DOCS:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", doc.read_text()):
            if not target.startswith(("http://", "https://")) and not (
                    doc.parent / target).exists():
                missing.append(f"{doc.relative_to(REPO)} -> {target}")
    assert not missing, missing


def test_the_python_guide_lists_every_signal_with_its_unit_topic_and_honesty():
    from alfa_bench.data import SIGNALS

    rows = {line.split("|")[1].strip().strip("`"): line
            for line in (REPO / "docs/python.md").read_text().splitlines()
            if line.startswith("| `")}
    for name, signal in SIGNALS.items():
        assert name in rows, name
        cells = [c.strip() for c in rows[name].split("|")[1:-1]]
        assert cells[1] == signal.unit and f"`{signal.topic}`" in cells[2], name
        assert cells[4].startswith("**no**") == (signal.kind == "actuator"), name


def _slug(heading: str) -> str:
    """A Markdown heading's anchor, as GitHub makes it."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def test_every_anchor_names_a_heading():
    missing = []
    for doc in DOCS:
        for target, anchor in re.findall(r"\]\(([^)#\s]*\.md)#([^)\s]+)\)", doc.read_text()):
            text = (doc.parent / target).read_text()
            slugs = {_slug(h) for h in re.findall(r"^#+ (.+)$", text, re.M)}
            if anchor not in slugs:
                missing.append(f"{doc.relative_to(REPO)} -> {target}#{anchor}")
    assert not missing, missing


def test_the_test_times_live_in_benchmarks():
    """How long the test tiers take changes with every test added: the guide points to
    BENCHMARKS.md, where it is measured and dated, instead of quoting it."""
    guide = (REPO / "docs/development.md").read_text()
    assert not re.findall(r"\b\d+ (?:s|tests)\b", guide)
    assert "../BENCHMARKS.md#the-test-tiers" in guide
    tiers = (REPO / "BENCHMARKS.md").read_text().split("## The test tiers\n")[1].split("\n## ")[0]
    assert re.search(r'\| fast \| `pytest -m "not workflow and not slow"` \| \d{4}-\d\d-\d\d.*'
                     r"\| \d+ s \| \d+ passed \|", tiers), tiers
