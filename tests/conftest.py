"""Shared fixtures: scenarios from text, and quick access to the shipped ones.

Property-based tests are derandomised: every run of the suite tries the same examples.
The on-disk cache is a fresh temporary directory for each run of the suite, and so is the
scratch space of the Dask clusters the tests start.
"""

import json
import math
import os
import re
import shutil
import sysconfig
import tempfile
import textwrap
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

from vplane_mj.cli import main
from vplane_mj.geometry.cache import CACHE_ENV
from vplane_mj.planning.protocol import registry
from vplane_mj.planning.protocol.registry import make_planner
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.scenario import build_scenario, load_scenario, parse_scenario, wall

# The tests keep their cached reference paths apart from the user's (and start without any).
_CACHE = tempfile.mkdtemp(prefix="vplane-mj-test-cache-")
os.environ[CACHE_ENV] = _CACHE
# Dask's workers keep their scratch space (dask-scratch-space, whose lock files outlive the
# workers) there too, not in the system's temporary directory: read when Dask is first imported,
# and by the worker processes, which inherit it.
os.environ["DASK_TEMPORARY_DIRECTORY"] = _CACHE


def pytest_sessionfinish(session, exitstatus):
    shutil.rmtree(_CACHE, ignore_errors=True)


settings.register_profile("deterministic", derandomize=True, database=None)
settings.load_profile("deterministic")


@pytest.fixture
def own_registry(monkeypatch):
    """A planner registry of this test's own: what it registers is gone afterwards."""
    monkeypatch.setattr(registry, "PLANNERS", registry._Planners())
    return registry.PLANNERS


@pytest.fixture
def console_script():
    """The path of an installed command (a package's console script) of the Python running the
    tests: in its scripts directory (a virtual environment's bin), whatever PATH holds."""

    def find(name: str) -> str:
        return str(Path(sysconfig.get_path("scripts")) / name)

    return find


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
def doc_examples():
    """The Python code blocks of sections (`## TITLE`) of a documentation page (docs/PAGE), in
    the page's order, joined into one script (a block indented in a list item is dedented)."""

    def blocks(page: str, *titles: str) -> str:
        text = (Path(__file__).parents[1] / "docs" / page).read_text(encoding="utf-8")
        sections = [text.split(f"\n## {title}\n", 1)[1].split("\n## ", 1)[0] for title in titles]
        return "\n".join(
            textwrap.dedent(block)
            for section in sections
            for block in re.findall(r"```python\n(.*?)```", section, re.S)
        )

    return blocks


@pytest.fixture(
    params=[
        ("paper_c_escape", 3, ("sensors.noise_std=0.02", "sensors.dropout=0.1")),
        (
            "paper_h_escape",
            3,
            ("sensors.pose=odometry", "sensors.odometry_noise=0.01", "run.time_limit_s=40"),
        ),
    ],
    ids=["noisy_sonar", "odometry"],
)
def vplane_run(request, tmp_path):
    """A `vplane-mj run` of a built-in scenario with faults: (name, seed, overrides, its summary,
    a fresh `vplane` planner of the same scenario), for environments driven by that planner."""
    name, seed, overrides = request.param
    sets = [arg for override in overrides for arg in ("--set", override)]
    main(["run", name, "--seed", str(seed), *sets, "--no-log", "--no-render", "--out", str(tmp_path)])
    expected = json.loads((tmp_path / f"{name}-vplane-{seed}.json").read_text())
    scenario = load_scenario(name, list(overrides))
    planner = make_planner(scenario.planner, scenario.planner_params, robot_radius_m())
    return name, seed, list(overrides), expected, planner


@pytest.fixture
def steer_to_goal():
    """A policy on an environment's observation alone: full speed, turning toward the goal in
    the robot frame (body speed m/s, turn rate rad/s)."""

    def policy(observation):
        x, y = observation["goal"]
        return np.array([0.5, 3.0 * math.atan2(y, x)])

    return policy


@pytest.fixture
def walled_off():
    """A 4 x 3 m arena cut in two by a wall between the start and the goal: no way through,
    so an episode ends at its 8 s time limit (the environments' truncation)."""
    return build_scenario(
        "blocked",
        size=(4.0, 3.0),
        start=(0.8, 1.5),
        goal=(3.4, 1.5),
        obstacles=[wall((2.0, 0.0), (2.0, 3.0), thickness=0.1)],
        run={"time_limit_s": 8.0},
    )
