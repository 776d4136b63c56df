"""Closed-loop runs in generated BARN-like worlds (fixed seeds): where the paper's rules place the
virtual objective, and the clutter extension `vplane_plus`."""

from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from vplane_mj.geometry import shapes
from vplane_mj.geometry.reference import shortest_path
from vplane_mj.planning.protocol.events import EventKind
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.scenario import parse_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.worlds.families import generate

pytestmark = pytest.mark.slow  # a long suite: `python -m pytest -m slow` runs it

RADIUS = robot_radius_m()


class Escapes:
    """Where the robot was and where the objective went, at every escape started."""

    def __init__(self):
        self.position = None
        self.placed = []

    def on_tick(self, tick):
        self.position = tick.position.copy()

    def on_event(self, time_s, event):
        if event.kind == EventKind.ESCAPE_STARTED:
            self.placed.append((self.position, np.array(event.data["objective"])))


def misplaced(toml: str, robot: np.ndarray, objective: np.ndarray) -> str | None:
    """Why the robot cannot go to `objective` in the true world, or None when it can."""
    scenario = parse_scenario(toml, "world.toml")
    width, height = scenario.world.size
    if not (0 <= objective[0] <= width and 0 <= objective[1] <= height):
        return "outside the arena"
    footprints = shapes.scene_footprints(scenario.world.obstacles, scenario.world.size)
    if footprints.distance(objective[None])[0] <= RADIUS:
        return "on an obstacle"
    way = [f"robot.start=[{robot[0]}, {robot[1]}]", f"robot.goal=[{objective[0]}, {objective[1]}]"]
    touching = footprints.distance(robot[None])[0] <= RADIUS  # (then there is no reference path)
    if not touching and shortest_path(parse_scenario(toml, "world.toml", way), RADIUS) is None:
        return "unreachable"
    return None


def _run(job):
    toml, planner = job
    watcher = Escapes()
    summary = run_scenario(
        parse_scenario(toml, "world.toml", [f"planner.name={planner}"]), (watcher,)
    ).summary
    problems = [why for robot, objective in watcher.placed if (why := misplaced(toml, robot, objective))]
    return planner, summary.success, len(watcher.placed), problems


@pytest.fixture(scope="module")
def barn_worlds():
    cases = generate("barn", 9, 0)
    return [cases[k].toml() for k in (0, 2, 8)]


def test_vplane_plus_places_objectives_only_where_the_robot_can_go(barn_worlds):
    """The paper's rule puts objectives outside the arena or on obstacles in these worlds; the
    extension's are free, inside and reachable, and it reaches every goal without a collision."""
    jobs = [(toml, "vplane_plus") for toml in barn_worlds] + [(barn_worlds[2], "vplane")]
    with ProcessPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(_run, jobs))
    *plus, paper = results
    assert all(success for _, success, _, _ in plus)
    assert sum(placed for _, _, placed, _ in plus) >= 2  # escapes did happen
    assert [problem for _, _, _, problems in plus for problem in problems] == []
    assert paper[3], "the world no longer shows the paper's misplaced objective"
