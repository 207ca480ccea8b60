"""The workflow config and its schema, shipped inside the package (``config.yaml``,
``schema.yaml`` beside this file): the runs, the scoring defaults (deadline, subsets,
calibration, pools) and where the data is looked for. Snakemake reads the same files
(``configfile: "config/config.yaml"``), so a plain install and a checkout score alike.

:func:`load_config` reads a config and checks it against the schema; a config that
breaks it ends on :class:`ConfigError`, whose message says which key, where it is set,
and what is allowed there (:func:`config_problem`, which the workflow prints too).
"""

from __future__ import annotations

import difflib
import os
from importlib.resources import files
from pathlib import Path

import yaml

__all__ = ["CONFIG_FILE", "SCHEMA_FILE", "ConfigError", "config_problem", "load_config"]

#: the config the package ships: the workflow's ``config/config.yaml``
CONFIG_FILE = Path(str(files(__name__) / "config.yaml"))
#: its schema
SCHEMA_FILE = Path(str(files(__name__) / "schema.yaml"))


class ConfigError(ValueError):
    """A config that breaks its schema: the key, where it is set, what is allowed."""


def load_config(path: str | os.PathLike | None = None) -> dict:
    """The config at ``path`` (default: the one the package ships,
    :data:`CONFIG_FILE`), checked against the package's schema.

    Raises
    ------
    FileNotFoundError
        Where ``path`` is not a file, naming it.
    ConfigError
        Where the config breaks the schema (:func:`config_problem`)."""
    path = CONFIG_FILE if path is None else Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"config: {path} is not a file; pass load_config() the path "
                                f"of a config.yaml, or none for the one shipped ({CONFIG_FILE})")
    config = yaml.safe_load(path.read_text())
    if (problem := config_problem(config, SCHEMA_FILE, [path])) is not None:
        raise ConfigError(problem)
    return config


def _found_in(files, path: list) -> str:
    """Which of the config ``files`` sets the key at ``path`` (the last one wins)."""
    found = None
    for f in files:
        node = yaml.safe_load(Path(f).read_text()) if Path(f).is_file() else None
        for key in path:
            node = node.get(key) if isinstance(node, dict) and key in node else None
            if node is None:
                break
        else:
            found = f
    return f"in {found}" if found else "given with --config"


def config_problem(config: dict, schema_path: str | Path, files) -> str | None:
    """The first way ``config`` breaks its schema, in words: the key and where it is
    set (which of the config ``files``), and for an unknown key the keys allowed
    there, the nearest first; None if it does not."""
    import jsonschema
    from jsonschema.exceptions import best_match

    schema = yaml.safe_load(Path(schema_path).read_text())
    error = best_match(jsonschema.Draft202012Validator(schema).iter_errors(config))
    if error is None:
        return None
    path = list(error.absolute_path)
    if error.validator == "additionalProperties":
        allowed = sorted(error.schema.get("properties", {}))
        key = sorted(set(error.instance) - set(allowed))[0]
        near = difflib.get_close_matches(key, allowed, n=1)
        under = ".".join(map(str, path)) or "the top level"
        return (f"config: unknown key {key!r} under {under} ({_found_in(files, [*path, key])})."
                + (f" Did you mean {near[0]!r}?" if near else "")
                + f"\nAllowed there: {', '.join(allowed)}.")
    name = ".".join(map(str, path)) or "(top level)"
    message = error.message if len(error.message) < 200 else error.message[:200] + " ..."
    return f"config {name}: {message} ({_found_in(files, path)})."
