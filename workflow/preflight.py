"""What the workflow checks before any job runs, ending on one message that says what
to do: the ALFA folder it was pointed at (the config against its schema is
:func:`alfa_bench.config.config_problem`, which the Python route shares)."""

from __future__ import annotations

import sys
from pathlib import Path

from alfa_bench.data.flight import entries, not_a_flight

__all__ = ["alfa_dir_problem", "failure_message", "stop"]


def stop(message: str) -> None:
    """End the run on ``message``, its last lines, without a traceback."""
    print(f"\n{message}", file=sys.stderr)
    sys.exit(1)


def _entries(n: int) -> str:
    return f"{n} entry" if n == 1 else f"{n} entries"


def alfa_dir_problem(alfa_dir: Path, source: str) -> str | None:
    """Why ``alfa_dir`` (set by ``source``: ``ALFA_DIR`` or the config's ``alfa_dir``)
    cannot be ALFA's folder, and what to do; None if its ``processed/`` holds a
    flight folder (whether its files read, the manifest job says)."""
    processed = alfa_dir / "processed"
    todo = (f"What to do: set {source} to the folder that holds ALFA's processed/ "
            "(its flights are processed/carbonZ_*), or unset it to download and verify "
            "the archive.")
    if not alfa_dir.is_dir():
        return f"{source} is {alfa_dir}, which does not exist.\n{todo}"
    if not processed.is_dir():
        held = sorted(p.name for p in alfa_dir.iterdir())
        seen = (f"it holds {_entries(len(held))} ({', '.join(held[:5])}"
                f"{', ...' if len(held) > 5 else ''})" if held else "it is empty")
        return f"{source} is {alfa_dir}, which has no processed/ folder: {seen}.\n{todo}"
    found = entries(processed)
    if not found:
        return f"{source} is {alfa_dir}, whose processed/ folder is empty.\n{todo}"
    why = {p.name: not_a_flight(p) for p in found}
    if all(why.values()):
        first = next(iter(why))
        return (f"{source} is {alfa_dir}: no entry of its processed/ is a flight folder "
                f"({_entries(len(why))}; the first, {first}: {why[first]}).\n{todo}")
    return None


def failure_message(source: str, alfa_dir: Path) -> str | None:
    """What a failed run's last lines say, from the logs of the jobs that can fail on
    the data's folder: the download's error, or the manifest's finding no flight that
    reads under ``alfa_dir`` (set by ``source``); None when neither failed so."""
    download = Path("results/logs/download_alfa.log")
    if download.is_file() and "download failed: " in (text := download.read_text()):
        why = text.split("download failed: ", 1)[1].split("\n", 1)[0]
        return f"The ALFA download failed: {why}\nDetails: {download}"
    manifest = Path("results/logs/manifest.log")
    if manifest.is_file() and "no readable flights under " in (text := manifest.read_text()):
        first = next((line.split("excluded: ", 1)[1] for line in text.splitlines()
                      if " excluded: " in line), "no entry is a flight folder")
        counted = text.split("no readable flights under ", 1)[1].split("\n", 1)[0]
        return (f"{source} is {alfa_dir}: no flight under its processed/ can be read "
                f"({counted.split('(', 1)[-1].rstrip(')')}); the first: {first}\n"
                f"What to do: set {source} to the folder that holds ALFA's processed/, or "
                f"unset it to download and verify the archive.\nDetails: {manifest}")
    return None
