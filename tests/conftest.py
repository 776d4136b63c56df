"""Shared fixtures: scenarios from text, and quick access to the shipped ones.

Property-based tests are derandomised: every run of the suite tries the same examples.
The on-disk cache is a fresh temporary directory for each run of the suite.
"""

import os
import re
import shutil
import tempfile
from pathlib import Path

import pytest
from hypothesis import settings

from vplane_mj.cache import CACHE_ENV
from vplane_mj.scenario import load_scenario, parse_scenario

# The tests keep their cached reference paths apart from the user's (and start without any).
_CACHE = tempfile.mkdtemp(prefix="vplane-mj-test-cache-")
os.environ[CACHE_ENV] = _CACHE


def pytest_sessionfinish(session, exitstatus):
    shutil.rmtree(_CACHE, ignore_errors=True)


settings.register_profile("deterministic", derandomize=True, database=None)
settings.load_profile("deterministic")


@pytest.fixture
def scenario_from():
    """Build a Scenario from TOML text (validated like a file)."""

    def build(text: str, overrides=()):
        return parse_scenario(text, "test.toml", list(overrides))

    return build


@pytest.fixture
def shipped():
    """Load a shipped scenario by name, with optional --set style overrides."""

    def load(name: str, *overrides: str):
        return load_scenario(name, list(overrides))

    return load


@pytest.fixture
def readme_examples():
    """The Python code blocks of a README section (`## TITLE`), joined into one script."""

    def blocks(title: str) -> str:
        text = (Path(__file__).parents[1] / "README.md").read_text(encoding="utf-8")
        section = text.split(f"\n## {title}\n", 1)[1].split("\n## ", 1)[0]
        return "\n".join(re.findall(r"```python\n(.*?)```", section, re.S))

    return blocks
