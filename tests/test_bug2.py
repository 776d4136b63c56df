"""Bug2: the mode switches on synthetic sonar scans, and whole runs in MuJoCo."""

import math

import numpy as np
import pytest

from vplane_mj.geometry import shapes, synthetic
from vplane_mj.planning.planners import bug2
from vplane_mj.planning.protocol.types import Observation
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.robots.profiles import DEFAULT
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.control import heading_command
from vplane_mj.sim.loop import run_scenario

ENCLOSURE = (  # a closed square of walls around (4, 3): x, y in [3.4, 4.6] x [2.4, 3.6]
    shapes.Wall((3.4, 2.4), (3.4, 3.6), 0.1),
    shapes.Wall((4.6, 2.4), (4.6, 3.6), 0.1),
    shapes.Wall((3.4, 2.4), (4.6, 2.4), 0.1),
    shapes.Wall((3.4, 3.6), (4.6, 3.6), 0.1),
)

INFO_KEYS = {"hit_distance_m", "wall_distance_m", "mline_tolerance_m", "max_follow_s"}


def planner(**overrides) -> bug2.Bug2Planner:
    return bug2.Bug2Planner.build(overrides, robot_radius_m())


def observe(footprints, position, yaw, goal, time_s=0.0) -> Observation:
    position = np.asarray(position, float)
    ranges = synthetic.scan(footprints, position, yaw)
    return Observation(
        time_s, position, yaw, np.asarray(goal, float), 0.15, synthetic.BEARINGS, ranges, synthetic.BEAM
    )


def drive(footprints, start, goal, seconds, plan=None, dt=0.05):
    """A kinematic unicycle under the real heading control, on synthetic scans; (planner, decisions)."""
    plan = plan or planner()
    position, yaw = np.asarray(start, float), math.atan2(goal[1] - start[1], goal[0] - start[0])
    decisions = []
    for tick in range(int(seconds / dt)):
        obs = observe(footprints, position, yaw, goal, tick * dt)
        decision = plan.step(obs)
        decisions.append((position.copy(), decision))
        if decision.gave_up or obs.distance_to_goal() <= obs.goal_tolerance:
            break
        v, w = heading_command(*decision.force, yaw, DEFAULT.gains, DEFAULT.limits)
        position = position + v * dt * np.array([math.cos(yaw), math.sin(yaw)])
        yaw += w * dt
    return plan, decisions


def test_params_have_defaults_units_and_docs():
    info = bug2.Bug2Planner.info()
    assert set(info.params) >= INFO_KEYS
    for param in info.params.values():
        assert param.doc and param.check(param.default) is None
    assert info.name == "bug2" and "Lumelsky" in info.citation


def test_the_m_line_runs_from_the_first_position_to_the_goal():
    plan = planner()
    with pytest.raises(RuntimeError, match="no m-line before its first step"):
        plan.mline_offset(np.zeros(2))
    plan.step(observe(shapes.scene_footprints([]), (1.0, 3.0), 0.0, (5.0, 3.0)))
    assert plan.mline_offset(np.array([2.0, 3.5])) == pytest.approx(0.5)  # left of the line
    assert plan.mline_offset(np.array([4.0, 2.0])) == pytest.approx(-1.0)
    plan.step(observe(shapes.scene_footprints([]), (2.0, 3.5), 0.0, (5.0, 3.0), 0.1))
    assert plan.mline_offset(np.array([2.0, 3.5])) == pytest.approx(0.5)  # the line stays


def test_goes_to_goal_in_the_open_and_follows_near_a_wall():
    wall = shapes.scene_footprints([shapes.Wall((3.0, 1.0), (3.0, 5.0), 0.1)])
    plan = planner()
    far = plan.step(observe(wall, (1.0, 3.0), 0.0, (5.0, 3.0)))
    assert far.mode == "go_to_goal" and not far.events
    assert far.force[0] > 0.9 and abs(far.force[1]) < 1e-9
    near = plan.step(observe(wall, (2.6, 3.0), 0.0, (5.0, 3.0), 1.0))
    assert near.mode == "following" and near.events and "hit" in near.events[0].text
    assert plan.hit_distance == pytest.approx(2.4)
    # Turning left with the wall on the right: the force points up along the wall.
    assert near.force[1] > 0.5 and near.force[1] > abs(near.force[0])


@pytest.mark.parametrize("open_side", [1, -1])
def test_a_laser_turns_toward_the_side_it_hears_nothing_from(open_side):
    # A post right ahead; on one side walls 4 m off, on the other nothing within the laser's
    # 30 m but an echo 6 m off: the side without echoes is the freer one.
    laser = synthetic.LAYOUTS["jackal_laser"]
    side = np.sign(laser.bearings)
    ranges = np.where(side == -open_side, 4.0, np.nan)
    ranges[np.flatnonzero(side == open_side)[::50]] = 6.0
    ranges[np.abs(laser.bearings) < 0.2] = 0.3
    obs = Observation(0.0, np.zeros(2), 0.0, np.array([5.0, 0.0]), 0.15, laser.bearings, ranges, laser.beam)
    decision = planner(follow_side=0).step(obs)
    assert decision.mode == "following"
    assert ("turning left" if open_side == 1 else "turning right") in decision.events[0].text


def test_follows_a_wall_around_its_end_and_leaves_on_the_m_line():
    wall = shapes.scene_footprints([shapes.Wall((3.0, 1.5), (3.0, 4.5), 0.1)])
    _, decisions = drive(wall, (1.0, 3.0), (5.0, 3.0), 60.0)
    modes = [d.mode for _, d in decisions]
    assert "following" in modes and modes[-1] == "go_to_goal"
    assert np.hypot(*(decisions[-1][0] - (5.0, 3.0))) <= 0.15
    clearance = wall.distance(np.array([p for p, _ in decisions]))
    assert clearance.min() > 0.2  # robot radius 0.11 m


def test_gives_up_on_a_goal_enclosed_by_walls():
    walls = shapes.scene_footprints(ENCLOSURE)
    _, decisions = drive(walls, (1.0, 3.0), (4.0, 3.0), 120.0)
    last = decisions[-1][1]
    assert last.gave_up and any("loop" in e.text for e in last.events)
    assert "following" in [d.mode for _, d in decisions]
    assert decisions[-1][0][0] < 3.4  # still outside the enclosure


def test_gives_up_after_max_follow_s():
    walls = shapes.scene_footprints(ENCLOSURE)
    _, decisions = drive(walls, (1.0, 3.0), (4.0, 3.0), 60.0, planner(max_follow_s=5.0))
    last = decisions[-1][1]
    assert last.gave_up and any("following for" in e.text for e in last.events)


@pytest.mark.parametrize("name", ["paper_c_escape", "paper_c_avoid"])
def test_escapes_the_c_trap_where_apf_is_stuck(name):
    apf = run_scenario(load_scenario(name, ["planner.name=apf"])).summary
    assert not apf.reached
    result = run_scenario(load_scenario(name, ["planner.name=bug2"]))
    summary = result.summary
    assert summary.reached and summary.collisions == 0
    assert summary.min_clearance_m > 0.05
    assert "following" in result.modes


def test_open_field_is_a_straight_line():
    summary = run_scenario(load_scenario("open_field", ["planner.name=bug2"])).summary
    assert summary.reached and summary.collisions == 0
    assert summary.path_length_m <= 1.1 * math.hypot(4.0, 4.0)


def test_gives_up_in_physics_on_an_enclosed_goal(scenario_from):
    walls = "\n".join(
        f'[[world.obstacles]]\nkind = "wall"\nfrom = {list(w.start)}\nto = {list(w.end)}\nthickness = 0.1\n'
        for w in ENCLOSURE
    )
    text = (
        'format = 1\nname = "enclosed"\n[world]\nsize = [6.0, 6.0]\n'
        f"{walls}[robot]\nstart = [1.0, 3.0]\ngoal = [4.0, 3.0]\n"
        '[planner]\nname = "bug2"\n[run]\ntime_limit_s = 90\n'
    )
    summary = run_scenario(scenario_from(text)).summary
    assert summary.outcome == "stuck" and summary.collisions == 0
