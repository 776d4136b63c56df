"""No inf or NaN reaches the wheels: adversarial inputs to every planner, and the run loop's guards."""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from vplane_mj.planning.motion import fields
from vplane_mj.planning.planners.vplane_geometry import (
    escape_direction,
    make_plane,
    plane_force,
    virtual_objective,
)
from vplane_mj.planning.protocol import registry
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.types import Decision, Observation
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.robots.profiles import DEFAULT
from vplane_mj.sim import control
from vplane_mj.sim import loop as sim
from vplane_mj.sim.world import build_model

BEARINGS = np.arange(16) * (2 * math.pi / 16)
coordinate = st.sampled_from([0.0, 1e-12, -1e-12, 5.0, 5.0 + 1e-9, 1e6])
reading = st.one_of(
    st.just(math.nan),
    st.sampled_from([0.0, 1e-12, 1e-3, 0.1, 0.11]),
    st.floats(min_value=0.0, max_value=20.0, allow_nan=False),
)
observation = st.fixed_dictionaries(
    {
        "position": st.tuples(coordinate, coordinate),
        "yaw": st.sampled_from([0.0, math.pi, -math.pi, 1e6]),
        "ranges": st.lists(reading, min_size=16, max_size=16),
        "goal_offset": st.sampled_from([(0.0, 0.0), (1e-12, 0.0), (0.05, 0.0), (3.0, -4.0)]),
    }
)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(sorted(registry.PLANNERS)), st.lists(observation, min_size=1, max_size=25))
def test_every_planner_gives_finite_forces_on_adversarial_scans(name, ticks):
    """Echoes at zero distance, a robot on its goal or on an echo, far-away poses, huge yaw."""
    planner = registry.make_planner(name, {}, robot_radius_m())
    for tick, seen in enumerate(ticks):
        position = np.array(seen["position"])
        goal = position + np.array(seen["goal_offset"])
        ranges = np.array(seen["ranges"])
        obs = Observation(0.05 * tick, position, seen["yaw"], goal, 0.15, BEARINGS, ranges, math.radians(20))
        decision = planner.step(obs)
        assert np.all(np.isfinite(decision.force)), (name, tick, decision)
        for part in decision.components.values():
            assert np.all(np.isfinite(part)), (name, tick, decision.components)
        v, omega = control.heading_command(*decision.force, seen["yaw"], DEFAULT.gains, DEFAULT.limits)
        assert math.isfinite(v) and math.isfinite(omega)


def test_firas_forces_stay_finite_at_zero_distance():
    here = np.array([1.0, 1.0])
    assert np.all(np.isfinite(fields.repulsive_force(here, np.array([[1.0, 1.0]] * 3), 1.0, 1.0)))
    assert np.all(fields.attractive_force(here, here, 1.0, 1.0) == 0.0)
    assert math.isfinite(fields.repulsive_potential(here, here[None, :], 1.0, 1.0))


@pytest.mark.parametrize(
    ("e2", "robot", "goal"),
    [
        ((2.0, 3.0), (2.0, 3.0), (2.0, 3.0)),  # every point coincides
        ((2.0, 3.0), (1.0, 3.0), (5.0, 3.0)),  # the two extreme points coincide
        ((2.0, 5.0), (2.0, 4.0), (2.0, 4.0)),  # the robot on the plane, on its goal
    ],
)
def test_virtual_plane_geometry_with_coincident_points_is_finite(e2, robot, goal):
    e1, e2, robot, goal = np.array([2.0, 3.0]), np.array(e2), np.array(robot), np.array(goal)
    trap = np.array([[2.5, 3.0], [2.5, 4.0], [2.0, 3.0]])
    plane = make_plane(e1, e2, trap, robot, goal, extend=0.1)
    assert np.hypot(*plane.normal) == pytest.approx(1.0)
    assert np.all(np.isfinite(escape_direction(robot, e1, e2, goal)))
    assert np.all(np.isfinite(virtual_objective(robot, e1, e2, goal, plane, 0.3)))
    assert np.all(np.isfinite(plane_force(robot, plane, 1.0, 0.5, 0.05, 0.3)))


@pytest.mark.parametrize("force", [(math.nan, 0.0), (math.inf, 1.0), (-math.inf, math.inf), (0.0, 0.0)])
def test_heading_control_stops_on_a_force_without_a_direction(force):
    assert control.heading_command(*force, 0.3, DEFAULT.gains, DEFAULT.limits) == (0.0, 0.0)


class _BrokenPlanner(Planner):
    """A planner whose force turns to NaN after a second of driving toward the goal."""

    name = "broken"
    summary = "NaN after a second"
    citation = ""

    def step(self, obs):
        direction = (obs.goal - obs.position) / max(obs.distance_to_goal(), 1e-9)
        return Decision(force=direction if obs.time_s < 1.0 else np.array([math.nan, 0.0]), mode="normal")


def test_a_non_finite_planner_force_ends_the_run_as_error(shipped, monkeypatch):
    monkeypatch.setattr(sim, "make_planner", lambda _name, _params, body: _BrokenPlanner.build({}, body))
    summary = sim.run_scenario(shipped("open_field")).summary
    assert summary.outcome == "error" and not summary.reached
    assert "non-finite force at t = 1.000 s" in summary.message
    assert summary.sim_time_s == pytest.approx(1.0)


def test_an_unstable_simulation_ends_as_error_with_mujocos_warning(shipped, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)  # MuJoCo writes its warning to MUJOCO_LOG.TXT in the working directory

    def unstable(scenario, **options):
        model = build_model(scenario, **options)
        model.dof_damping[:] = -1e6  # negative damping: the state blows up within a step
        return model

    monkeypatch.setattr(sim, "build_model", unstable)
    summary = sim.run_scenario(shipped("open_field")).summary
    assert summary.outcome == "error"
    assert summary.message.startswith("MuJoCo warning at t = ")
    assert "unstable" in summary.message
    assert summary.sim_time_s < 0.1  # detected at the first control tick, not after the time limit
