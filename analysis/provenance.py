"""The provenance block every result carries: the code version, the packages, the config
and the inputs (each flight's checksum, the calibration folds). Files are stamped with it
by :mod:`alfa_bench.outputs.provenance`."""

from __future__ import annotations

import subprocess
from functools import cache
from importlib import metadata
from pathlib import Path

import pandas as pd

from .held_out import TooFewGroupsError, folds

__all__ = ["PACKAGES", "code_version", "package_versions", "provenance", "run_provenance"]

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


def provenance(config: dict, inputs: dict, calibration: dict | None = None) -> dict:
    """The provenance block stored in every result file."""
    return {"code": code_version(), "packages": package_versions(), "config": config,
            "inputs": inputs, "calibration": calibration}


def run_provenance(config: dict, manifest: pd.DataFrame,
                   calibrate_on: pd.DataFrame | None = None) -> dict:
    """The provenance of a file made from every flight of ``manifest``: code, packages,
    the whole workflow ``config``, each flight's checksum and the calibration folds
    (which flights, of ``calibrate_on`` if given, calibrated each group's methods)."""
    cal = config.get("calibration")
    train = manifest if calibrate_on is None else calibrate_on
    sha = dict(zip(manifest["flight"], manifest["sha256"], strict=True))
    sha |= dict(zip(train["flight"], train["sha256"], strict=True))
    folds_ = None
    if cal is not None:
        try:
            folds_ = {g: training for g, (_, training) in folds(train, cal["group_by"]).items()}
        except TooFewGroupsError:
            pass                        # no group can be left out: no folds to record
    return provenance(config, {"flight_sha256": sha},
                      calibration={**(cal or {}), "training_flights": folds_})
