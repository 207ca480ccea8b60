"""What a result was made from: code version, packages, config, inputs."""

from __future__ import annotations

import subprocess
from functools import cache
from importlib import metadata
from pathlib import Path

__all__ = ["PACKAGES", "code_version", "package_versions", "provenance"]

PACKAGES = ("alfa-bench", "numpy", "scipy", "pandas", "filterpy", "control", "scikit-learn",
            "rerun-sdk", "snakemake", "matplotlib")


@cache
def code_version() -> dict:
    """Project version and git commit (None outside a checkout), and if the tree is dirty."""
    root = Path(__file__).resolve().parent.parent

    def git(*args):
        try:
            return subprocess.run(["git", "-C", str(root), *args], capture_output=True,
                                  text=True, check=True).stdout.strip()
        except (OSError, subprocess.CalledProcessError):
            return None

    commit = git("rev-parse", "HEAD")
    dirty = bool(git("status", "--porcelain", "--untracked-files=no")) if commit else None
    return {"version": metadata.version("alfa-bench"), "git_commit": commit, "git_dirty": dirty}


@cache
def package_versions() -> dict:
    versions = {}
    for p in PACKAGES:
        try:
            versions[p] = metadata.version(p)
        except metadata.PackageNotFoundError:
            versions[p] = None
    return versions


def provenance(config: dict, inputs: dict) -> dict:
    """The provenance block stored in every result file."""
    return {"code": code_version(), "packages": package_versions(), "config": config,
            "inputs": inputs}
