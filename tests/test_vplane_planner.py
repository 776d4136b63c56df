"""The vplane planner on synthetic sonar scans (pure numpy, no physics)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vplane_mj.geometry import shapes
from vplane_mj.geometry.synthetic import BEAM, BEARINGS, scan
from vplane_mj.planning.protocol.events import EventKind
from vplane_mj.planning.protocol.registry import make_planner
from vplane_mj.planning.protocol.types import Observation

RADIUS = 0.11


def world_cup(angle):
    """A cup at (5, 5) opening toward local -x, turned by `angle`; the goal behind it."""
    cup = shapes.Cup((5.0, 5.0), width=1.6, depth=1.2, yaw=angle, thickness=0.1)
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    return cup, rot


def to_local(point, rot):
    return rot.T @ (np.asarray(point) - [5.0, 5.0])


def observe(footprints, position, yaw, goal, time_s):
    return Observation(
        time_s=time_s,
        position=np.asarray(position, float),
        yaw=yaw,
        goal=np.asarray(goal, float),
        goal_tolerance=0.15,
        bearings=BEARINGS,
        ranges=scan(footprints, position, yaw),
        beam_width=BEAM,
    )


def hold(planner, footprints, position, yaw, goal, start_s, seconds):
    """Keep the robot still for `seconds` at 20 Hz; return every decision."""
    return [
        planner.step(observe(footprints, position, yaw, goal, start_s + k * 0.05))
        for k in range(round(seconds * 20))
    ]


@settings(max_examples=8, deadline=None)
@given(st.floats(min_value=0.0, max_value=2 * math.pi))
def test_trapped_robot_escapes_through_the_mouth_for_any_orientation(angle):
    cup, rot = world_cup(angle)
    footprints = shapes.Footprints(cup.footprint())
    inside = rot @ [0.2, 0.0] + [5.0, 5.0]
    goal = rot @ [4.0, 0.0] + [5.0, 5.0]
    planner = make_planner("vplane", {}, RADIUS)
    decisions = hold(planner, footprints, inside, angle, goal, 0.0, 7.0)
    detected = [d for d in decisions if d.local_minimum]
    assert len(detected) == 1
    assert any(e.kind == EventKind.ESCAPE_STARTED for e in detected[0].events)
    assert decisions[-1].mode == "escaping"
    objective = to_local(planner.temp_goal, rot)
    assert objective[0] < -0.6 - RADIUS  # beyond the mouth (local x = -0.6), outside the trap
    assert abs(objective[1]) < 0.8

    # Reaching the objective completes the escape and creates the virtual plane.
    done = planner.step(observe(footprints, planner.temp_goal, angle + math.pi, goal, 7.1))
    assert done.escape_completed and planner.temp_goal is None
    (plane,) = planner.planes
    e1, e2 = to_local(plane.e1, rot), to_local(plane.e2, rot)
    assert max(e1[1], e2[1]) > 0.8 and min(e1[1], e2[1]) < -0.8  # it closes the whole mouth
    assert to_local(plane.e1 + plane.normal, rot)[0] < e1[0]  # its normal points out of the cup

    # Just outside the mouth, heading back in: the plane pushes outward.
    outside = rot @ [-0.9, 0.0] + [5.0, 5.0]
    decision = planner.step(observe(footprints, outside, angle, goal, 7.2))
    virtual = decision.components["virtual"]
    assert virtual @ plane.normal > 0
    assert decision.mode in ("normal", "avoiding")  # the target is active again


def test_planner_gives_up_after_its_escapes():
    cup, _ = world_cup(0.0)
    footprints = shapes.Footprints(cup.footprint())
    planner = make_planner("vplane", {"max_escapes": 1, "escape_timeout_s": 3.0}, RADIUS)
    decisions = hold(planner, footprints, (5.2, 5.0), 0.0, (9.0, 5.0), 0.0, 20.0)
    assert sum(d.local_minimum for d in decisions) >= 1
    gave_up = next(k for k, d in enumerate(decisions) if d.gave_up)
    started = [k for k, d in enumerate(decisions) for e in d.events if e.kind is EventKind.ESCAPE_STARTED]
    assert len(started) == 1 and started[0] < gave_up  # its one escape was tried, then it gave up


def test_approaching_a_cup_mouth_turns_toward_an_edge():
    cup, _ = world_cup(0.0)
    footprints = shapes.Footprints(cup.footprint())
    planner = make_planner("vplane", {}, RADIUS)
    goal = np.array([9.0, 5.0])
    avoiding = None
    for k in range(90):  # drive toward the mouth at 0.5 m/s, from 2.5 m to 0.3 m before it
        x = 1.9 + 0.025 * k
        decision = planner.step(observe(footprints, (x, 5.0), 0.0, goal, k * 0.05))
        if decision.mode == "avoiding":
            avoiding = planner.avoid_waypoint
            break
    assert avoiding is not None, "the concave obstacle ahead was not recognised"
    assert abs(avoiding[1] - 5.0) > 0.8 + RADIUS  # beside an arm, not into the mouth
    assert avoiding[0] < 4.4 + 0.5  # near the mouth's edge, not behind the cup


def test_planner_never_returns_non_finite_forces():
    planner = make_planner("vplane", {}, RADIUS)
    for k in range(40):  # an echo at (almost) zero range every tick, robot not moving
        ranges = np.full(16, np.nan)
        ranges[k % 16] = 1e-9
        obs = Observation(
            k * 0.05, np.array([1.0, 1.0]), 0.0, np.array([1.0, 1.0 + 1e-12]), 0.15, BEARINGS, ranges, BEAM
        )
        decision = planner.step(obs)
        assert np.all(np.isfinite(decision.force))


@pytest.mark.parametrize("name", ["apf", "vplane"])
def test_planner_parameters_resolve_with_defaults(name):
    planner = make_planner(name, {"influence": 0.5}, RADIUS)
    assert planner.params.influence == 0.5
    assert planner.params.attract_gain == 0.5
