"""Navigation outcomes in MuJoCo (fixed seeds): vplane against apf on the paper's traps."""

import math
import statistics
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from vplane_mj.geometry import shapes
from vplane_mj.planning.protocol.events import EventKind
from vplane_mj.scenario import load_scenario, parse_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.worlds.families import cup_case, rotated, trap_suite

pytestmark = pytest.mark.slow  # a long suite: `python -m pytest -m slow` runs it

PAPER = ["paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape"]


class Events:
    def __init__(self):
        self.events = []

    def on_tick(self, tick):
        pass

    def on_event(self, time_s, event):
        self.events.append((time_s, event))


def inside_trap(scenario, positions):
    """For each position: is the robot's centre inside a cup's open interior?"""
    interiors = [r for ob in scenario.world.obstacles if hasattr(ob, "interior") for r in ob.interior()]
    return shapes.Footprints(interiors).distance(positions) < 0


@pytest.mark.parametrize("planner", ["vplane", "vplane_plus"])
@pytest.mark.parametrize("name", PAPER)
def test_vplane_reaches_the_goal_in_the_paper_scenarios(shipped, name, planner):
    scenario = shipped(name, f"planner.name={planner}")
    summary = run_scenario(scenario).summary
    straight = math.dist(scenario.robot.start, scenario.robot.goal)
    assert summary.outcome == "reached" and summary.success, summary
    assert summary.collisions == 0
    assert straight - 0.2 < summary.path_length_m < 2.0 * straight
    assert summary.min_clearance_m > 0.05


@pytest.mark.parametrize("name", ["paper_c_avoid", "paper_h_avoid"])
def test_histogram_avoidance_passes_the_cup_without_entering(shipped, name):
    scenario = shipped(name)
    result = run_scenario(scenario)
    assert result.summary.reached and result.summary.local_minima == 0
    assert not inside_trap(scenario, result.positions).any()
    assert "avoiding" in result.modes


@pytest.mark.parametrize("name", ["paper_c_escape", "paper_h_escape"])
def test_after_the_escape_the_robot_never_reenters_the_trap(shipped, name):
    scenario = shipped(name)
    watcher = Events()
    result = run_scenario(scenario, observers=(watcher,))
    assert result.summary.reached and result.summary.escapes >= 1
    escaped_at = min(t for t, e in watcher.events if e.kind == EventKind.ESCAPE_FINISHED)
    before = result.times < escaped_at
    assert inside_trap(scenario, result.positions[before]).any()  # it was trapped
    assert not inside_trap(scenario, result.positions[~before]).any()  # and never went back


def _run_case(job):
    toml, name, planner = job
    summary = run_scenario(parse_scenario(toml, name, [f"planner.name={planner}"])).summary
    return name, planner, summary.success, summary.time_to_goal_s, summary.path_length_m


def test_trap_suite_vplane_succeeds_where_apf_is_trapped():
    cases = trap_suite()
    planners = ("vplane", "vplane_plus", "apf")
    jobs = [(case.toml(), case.name, planner) for case in cases for planner in planners]
    with ProcessPoolExecutor(max_workers=2) as pool:
        rows = list(pool.map(_run_case, jobs))
    rate = {p: np.mean([ok for _, planner, ok, _, _ in rows if planner == p]) for p in planners}
    times = [t for _, planner, ok, t, _ in rows if planner == "vplane" and ok]
    print(
        f"\ntrap suite of {len(cases)}: vplane {rate['vplane']:.0%}, vplane_plus {rate['vplane_plus']:.0%}, "
        f"apf {rate['apf']:.0%}, vplane median time to goal {statistics.median(times):.1f} s"
    )
    assert rate["vplane"] >= 0.95
    assert rate["vplane_plus"] >= 0.95
    assert rate["apf"] <= 0.1


ROTATIONS_DEG = (37.0, 128.0, 211.0, 302.0)
"""Turns of the whole trap case about the arena's centre (deg), none a multiple of 90."""


@pytest.fixture(scope="module")
def unrotated_trap():
    """The U trap case with its mouth toward the start, and its run's summary."""
    case = cup_case("u_front", 0.0)
    return case, run_scenario(parse_scenario(case.toml(), "base.toml")).summary


def heading_deg(scenario) -> float:
    """The direction from the start to the goal (deg)."""
    (x0, y0), (x1, y1) = scenario.robot.start, scenario.robot.goal
    return math.degrees(math.atan2(y1 - y0, x1 - x0))


@pytest.mark.parametrize("angle", ROTATIONS_DEG)
def test_a_rotated_trap_gives_the_same_outcome(unrotated_trap, angle):
    case, base = unrotated_trap
    scenario = parse_scenario(rotated(case, angle).toml(), "rotated.toml")
    turn = heading_deg(scenario) - heading_deg(parse_scenario(case.toml(), "base.toml"))
    assert math.isclose(turn % 360.0, angle, abs_tol=1e-4)  # the case is turned, start and goal too
    assert scenario.world.obstacles[0].yaw == pytest.approx(math.radians(angle))
    turned = run_scenario(scenario).summary
    assert base.success and turned.success
    assert turned.escapes == base.escapes
    assert turned.path_length_m == pytest.approx(base.path_length_m, rel=0.2)


@pytest.mark.parametrize(
    "sensor, most_s",
    [
        ("sensors.kind=sonar", 120.0),  # read at the control rate
        ("sensors.kind=laser", 150.0),  # a scan every other tick
        ("robot.profile=turtlebot3_burger", 300.0),  # a scan every fourth tick
    ],
)
def test_vplane_plus_gives_up_on_a_walled_in_goal(sensor, most_s):
    """No way leads to the goal: vplane_plus ends `stuck` once its map has held no way for
    `no_way_patience_s`, however often its sensor scans (a scan handed to several ticks is
    folded into the map once: folded again at later poses it erased the walls, and the robot
    drove for the whole time limit)."""
    overrides = ["planner.name=vplane_plus", "run.time_limit_s=600", sensor]
    summary = run_scenario(load_scenario("walled_goal", overrides)).summary
    assert summary.outcome == "stuck", summary
    assert "the map has held no way to the goal" in summary.message
    assert summary.sim_time_s < most_s and summary.path_length_m < 60.0
    assert summary.collisions == 0
