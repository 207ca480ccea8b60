"""A config that breaks its schema is blamed where the bad key is set: the config file
that sets it last, or Snakemake's ``--config key=value`` override, which wins over
every file (config/__init__.py, ``config_problem``)."""

import pytest
import yaml
from workflow_runs import REPO, run_workflow

from alfa_bench.config import CONFIG_FILE, SCHEMA_FILE, config_problem


def _config(**changes) -> dict:
    config = yaml.safe_load(CONFIG_FILE.read_text())
    for key, value in changes.items():
        config[key] = {**config[key], **value} if isinstance(value, dict) else value
    return config


def test_a_bad_value_is_blamed_on_the_last_file_that_sets_it(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("strict: maybe\n")
    problem = config_problem(_config(strict="maybe"), SCHEMA_FILE, [CONFIG_FILE, bad])
    assert problem == f"config strict: 'maybe' is not of type 'boolean' (in {bad})."


def test_a_bad_value_given_with_config_is_blamed_on_the_override():
    """The shipped file sets ``strict`` too, but the override is what broke it."""
    problem = config_problem(_config(strict="maybe"), SCHEMA_FILE, [CONFIG_FILE],
                             {"strict": "maybe"})
    assert problem == ("config strict: 'maybe' is not of type 'boolean' "
                       '(given with --config strict="maybe").')


def test_an_unknown_key_given_with_config_is_blamed_on_the_override(tmp_path):
    other = tmp_path / "other.yaml"
    other.write_text("scoring:\n  deadline_s: 4.0\n")
    override = {"scoring": {"deadline_s": 4.0, "deadine_s": 5.0}}
    problem = config_problem(_config(**override), SCHEMA_FILE, [CONFIG_FILE, other],
                             override)
    assert problem.splitlines()[0] == (
        "config: unknown key 'deadine_s' under scoring (given with --config scoring="
        '{"deadline_s": 4.0, "deadine_s": 5.0}). Did you mean \'deadline_s\'?')


@pytest.mark.workflow
def test_the_workflow_blames_a_config_override(corpus, tmp_path):
    done = run_workflow(tmp_path, corpus.parent, "-n", "--configfile",
                        str(REPO / "config/config.yaml"), "--config", "strict=maybe",
                        ok=False)
    assert ("config strict: 'maybe' is not of type 'boolean' (given with --config "
            'strict="maybe").') in done.stderr, done.stderr
