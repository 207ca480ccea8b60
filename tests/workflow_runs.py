"""Running the workflow in a subprocess, and comparing two runs' results."""

import contextlib
import fcntl
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from recordings import content

REPO = Path(__file__).resolve().parent.parent
SNAKEMAKE = [sys.executable, "-m", "snakemake"]
#: held shared by every workflow run of the tests, and exclusively by
#: :func:`dry_run_with_changed` while it changes a module of the repo: a run on another
#: worker would otherwise record the change (a dirty tree in its provenance). Named for
#: the checkout, so that every test process on it shares it
SOURCES_LOCK = Path(tempfile.gettempdir()) / (
    f"alfa-bench-sources-{hashlib.sha256(str(REPO).encode()).hexdigest()[:12]}.lock")


@contextlib.contextmanager
def _sources(mode: int):
    with open(SOURCES_LOCK, "a") as lock:
        fcntl.flock(lock, mode)
        yield


def made_once(tmp_path_factory, name: str, make):
    """``make()``'s value (JSON), made by the first of the session's processes (the
    xdist workers) that asks; the others wait for it, then read it. A ``make`` that
    fails is tried again by the next to ask."""
    base = tmp_path_factory.getbasetemp()
    root = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base
    done = root / f"{name}.json"
    with open(root / f"{name}.lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not done.exists():
            done.write_text(json.dumps(make()))
        return json.loads(done.read_text())

#: a small injected grid for the tests (config/config.yaml's is for the real flights)
GRID = {"sensors": ["roll", "airspeed", "pitch_rate"],
        "faults": [{"kind": "drift", "magnitude": 0.5}, {"kind": "scale", "magnitude": 0.9},
                   {"kind": "stuck", "magnitude": 0.0}],
        "onsets": [0.5]}


def run_workflow(workdir: Path, alfa_dir: Path | None, *args: str,
                 target: str | list[str] = "all",
                 ok: bool | None = True, quiet: bool = True, env: dict | None = None
                 ) -> subprocess.CompletedProcess:
    """Run the workflow in ``workdir``; ``alfa_dir=None`` runs it as the README's first
    command does, without ALFA_DIR, so that it downloads the archive. ``ok`` is whether
    it must succeed (None: the caller checks)."""
    env = {k: v for k, v in (env or os.environ).items() if k != "ALFA_DIR"}
    if alfa_dir is not None:
        env["ALFA_DIR"] = str(alfa_dir)
    targets = [target] if isinstance(target, str) else list(target)
    cmd = [*SNAKEMAKE, *targets, "--cores", "2", "--snakefile", str(REPO / "Snakefile"),
           "--directory", str(workdir), "--configfile", str(REPO / "config/config.yaml"),
           *(["--quiet"] if quiet else []), *args]
    with _sources(fcntl.LOCK_SH):
        done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    assert ok is None or (done.returncode == 0) == ok, done.stdout + done.stderr
    return done


def dry_run_with_changed(module: Path, workdir: Path, overlay: Path, tag: str
                          ) -> subprocess.CompletedProcess:
    """``snakemake all -n`` over the run in ``workdir`` with ``module``'s text changed by
    one comment line (Snakemake compares small inputs by content), restored byte for
    byte, its times too, whatever the run did."""
    text, stat = module.read_bytes(), module.stat()
    with _sources(fcntl.LOCK_EX):
        try:
            module.write_bytes(text + f"# changed by {tag}\n".encode())
            env = {k: v for k, v in os.environ.items() if k != "ALFA_DIR"}
            return subprocess.run([*SNAKEMAKE, "all", "-n", "--cores", "2", "--snakefile",
                                   str(REPO / "Snakefile"), "--directory", str(workdir),
                                   "--configfile", str(REPO / "config/config.yaml"),
                                   str(overlay)], env=env, capture_output=True, text=True)
        finally:
            module.write_bytes(text)
            os.utime(module, ns=(stat.st_atime_ns, stat.st_mtime_ns))


def assert_same_results(a: Path, b: Path, part: bool = False) -> int:
    """Every result of run ``b`` is run ``a``'s, byte for byte, but the rerun recordings:
    rerun 0.41 draws its ids from the clock and orders its footer index by a hash map
    (docs/viewer.md), so their entities, times and values are compared. Logs, benchmarks
    and the runtime table hold times, which vary. ``b`` made every result ``a`` made,
    or with ``part`` some of them. Returns the number of files compared."""
    skip = {"logs", "benchmarks", "runtime"}
    files = sorted(p.relative_to(a) for p in (a / "results").rglob("*")
                   if p.is_file() and not skip & set(p.parts))
    files += sorted(p.relative_to(a) for p in (a / "paper/build").glob("*")
                    if p.suffix in {".md", ".tex", ".pdf"})
    made = sorted(p.relative_to(b) for p in (b / "results").rglob("*")
                  if p.is_file() and not skip & set(p.parts))
    if part:
        assert set(made) <= set(files), sorted(set(made) - set(files))
        files = made
    assert [f for f in files if f.parts[0] == "results"] == made
    for rel in files:
        if rel.suffix == ".rrd":
            assert content(a / rel) == content(b / rel), rel
        else:
            assert (a / rel).read_bytes() == (b / rel).read_bytes(), rel
    return len(files)
