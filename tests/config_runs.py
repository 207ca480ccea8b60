"""The config's runs, for tests repeated over them."""

from collections.abc import Callable, Hashable
from pathlib import Path

import yaml

CONFIG = yaml.safe_load((Path(__file__).resolve().parent.parent / "config/config.yaml")
                        .read_text())


def one_run_per(key: Callable[[dict], Hashable], runs=None) -> list[str]:
    """The first of the config's ``runs`` (all by default), by name, of each ``key`` of
    their specs: runs that agree on everything a test looks at test the same thing."""
    kept: dict[Hashable, str] = {}
    for name in sorted(runs if runs is not None else CONFIG["methods"]):
        kept.setdefault(key(CONFIG["methods"][name]), name)
    return sorted(kept.values())
