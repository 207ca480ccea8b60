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
import json
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


def _sets(node, path: list) -> bool:
    """Whether the nested mapping ``node`` sets the key at ``path``."""
    for key in path:
        if not isinstance(node, dict) or key not in node:
            return False
        node = node[key]
    return True


def _found_in(files, path: list, overrides: dict) -> str:
    """Where the key at ``path`` is set: by a ``--config`` override of ``overrides``
    (which win), else by the last of the config ``files`` that sets it."""
    if path and _sets(overrides, path):
        return f"given with --config {path[0]}={json.dumps(overrides[path[0]])}"
    found = [f for f in files if Path(f).is_file()
             and _sets(yaml.safe_load(Path(f).read_text()), path)]
    return f"in {found[-1]}" if found else "given with --config"


def config_problem(config: dict, schema_path: str | Path, files,
                   overrides: dict | None = None) -> str | None:
    """The first way ``config`` breaks its schema, in words: the key and where it is
    set (a ``--config`` override of ``overrides``, Snakemake's ``key=value`` pairs, or
    else which of the config ``files``), and for an unknown key the keys allowed there,
    the nearest first; None if it does not."""
    import jsonschema
    from jsonschema.exceptions import best_match

    overrides = overrides or {}
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
        where = _found_in(files, [*path, key], overrides)
        return (f"config: unknown key {key!r} under {under} ({where})."
                + (f" Did you mean {near[0]!r}?" if near else "")
                + f"\nAllowed there: {', '.join(allowed)}.")
    name = ".".join(map(str, path)) or "(top level)"
    message = error.message if len(error.message) < 200 else error.message[:200] + " ..."
    return f"config {name}: {message} ({_found_in(files, path, overrides)})."
