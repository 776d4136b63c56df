"""The escape's geometry in the plane's own frame: bisector, objective, corridor, plane force."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vplane_mj.planning.planners.vplane_geometry import (
    escape_direction,
    make_plane,
    plane_force,
    unit,
    virtual_objective,
)


def rotation(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def cup_in_frame(angle, offset=(3.0, 4.0)):
    """A cup of mouth e1 = (-0.6, -0.75), e2 = (-0.6, 0.75), back at x = 0.6, rotated."""
    rot, shift = rotation(angle), np.array(offset)
    e1 = rot @ [-0.6, -0.75] + shift
    e2 = rot @ [-0.6, 0.75] + shift
    walls = np.array(
        [rot @ [x, y] + shift for x, y in [(0.6, -0.7), (0.6, 0.0), (0.6, 0.7), (0.0, 0.75), (0.0, -0.75)]]
    )
    robot = rot @ [0.1, 0.0] + shift  # inside, near the back
    goal = rot @ [4.0, 0.3] + shift  # behind the back wall
    return e1, e2, walls, robot, goal


def test_bisector_inside_a_cup_points_out_of_the_mouth():
    e1, e2, _, robot, goal = cup_in_frame(0.0, (0.0, 0.0))
    assert escape_direction(robot, e1, e2, goal) == pytest.approx([-1.0, 0.0])


def test_bisector_is_flipped_away_from_the_goal_in_front_of_an_obstacle():
    # Robot outside, the obstacle's ends ahead of it, the goal beyond: escape goes back.
    robot, goal = np.zeros(2), np.array([5.0, 0.0])
    direction = escape_direction(robot, np.array([1.0, -1.0]), np.array([1.0, 1.0]), goal)
    assert direction == pytest.approx([-1.0, 0.0])


def test_cancelled_directions_fall_back_to_the_normal_away_from_the_goal():
    robot = np.zeros(2)
    direction = escape_direction(robot, np.array([0.0, -1.0]), np.array([0.0, 1.0]), np.array([3.0, 0.5]))
    assert direction == pytest.approx([-1.0, 0.0])


@settings(max_examples=60, deadline=None)
@given(st.floats(min_value=0.0, max_value=2 * math.pi))
def test_objective_lies_outside_the_trap_for_any_orientation(angle):
    e1, e2, walls, robot, goal = cup_in_frame(angle)
    plane = make_plane(e1, e2, walls, robot, goal)
    objective = virtual_objective(robot, e1, e2, goal, plane, clearance=0.26)
    _, out = plane.frame_coordinates(objective)
    assert out >= 0.26 - 1e-9
    # the normal points away from the trap: the back wall is on the inner side
    assert plane.frame_coordinates(walls[1])[1] < 0
    # and it is the mouth side: farther from the goal than the robot is
    assert np.hypot(*(objective - goal)) > np.hypot(*(robot - goal))


def test_objective_is_pushed_out_when_the_bisector_is_too_short():
    # A deep cup: max(l1, l2) along the bisector ends inside it.
    e1, e2 = np.array([-0.5, -0.3]), np.array([-0.5, 0.3])
    walls = np.array([[1.5, 0.0], [0.5, 0.3], [0.5, -0.3]])
    robot, goal = np.array([1.2, 0.0]), np.array([5.0, 0.0])
    plane = make_plane(e1, e2, walls, robot, goal)
    objective = virtual_objective(robot, e1, e2, goal, plane, clearance=0.3)
    assert plane.frame_coordinates(objective)[1] == pytest.approx(0.3)


def test_plane_is_extended_and_slides_toward_the_shorter_way():
    e1, e2 = np.array([0.0, -1.0]), np.array([0.0, 1.0])
    walls = np.array([[1.0, 0.0]])
    plane = make_plane(e1, e2, walls, np.array([0.5, 0.0]), np.array([4.0, 3.0]), extend=0.3)
    assert plane.length == pytest.approx(2.6)
    assert plane.normal == pytest.approx([-1.0, 0.0])
    assert plane.slide * plane.tangent == pytest.approx([0.0, 1.0])  # toward e2, nearer the goal


def test_corridor_activation_in_the_plane_frame():
    plane = make_plane(
        np.array([0.0, -1.0]), np.array([0.0, 1.0]), np.array([[1.0, 0.0]]), np.zeros(2), np.array([4.0, 0.0])
    )
    assert plane.in_corridor(np.array([-0.3, 0.0]), influence=0.6, margin=0.3)
    assert plane.in_corridor(np.array([-0.3, 1.25]), influence=0.6, margin=0.3)
    assert not plane.in_corridor(np.array([-0.3, 1.4]), influence=0.6, margin=0.3)
    assert not plane.in_corridor(np.array([-0.7, 0.0]), influence=0.6, margin=0.3)
    assert plane.in_corridor(np.array([0.5, 0.0]), influence=0.6, margin=0.3)  # inside the trap


def straight_plane():
    return make_plane(
        np.array([0.0, -1.0]), np.array([0.0, 1.0]), np.array([[1.0, 0.0]]), np.zeros(2), np.array([4.0, 0.5])
    )


def test_plane_force_points_outward_with_a_tangential_slide():
    plane = straight_plane()
    force = plane_force(np.array([-0.3, 0.0]), plane, gain=0.05, influence=0.6, step=0.05, slide_gain=1.0)
    outward = force @ plane.normal
    assert outward > 0
    assert force @ plane.tangent * plane.slide == pytest.approx(outward)
    no_slide = plane_force(np.array([-0.3, 0.0]), plane, 0.05, 0.6, 0.05, slide_gain=0.0)
    assert no_slide == pytest.approx(outward * plane.normal)


def test_plane_force_does_not_grow_with_the_number_of_points():
    plane = straight_plane()
    coarse = plane_force(np.array([-0.25, 0.2]), plane, 0.05, 0.6, 0.05, 0.0)
    fine = plane_force(np.array([-0.25, 0.2]), plane, 0.05, 0.6, 0.005, 0.0)
    assert np.linalg.norm(fine) == pytest.approx(np.linalg.norm(coarse), rel=0.03)


def test_plane_force_grows_toward_the_plane_and_vanishes_beyond_influence():
    plane = straight_plane()
    magnitudes = [
        np.linalg.norm(plane_force(np.array([-d, 0.0]), plane, 0.05, 0.6, 0.05, 0.0))
        for d in (0.1, 0.2, 0.4, 0.59)
    ]
    assert magnitudes == sorted(magnitudes, reverse=True)
    assert plane_force(np.array([-0.7, 0.0]), plane, 0.05, 0.6, 0.05, 1.0) == pytest.approx([0, 0])


@pytest.mark.parametrize("point", [(0.0, 0.0), (0.3, 0.0), (1e-12, -1.0)])
def test_plane_force_is_finite_and_outward_on_or_behind_the_plane(point):
    plane = straight_plane()
    force = plane_force(np.array(point), plane, 0.05, 0.6, 0.05, 1.0)
    assert np.all(np.isfinite(force)) and force @ plane.normal > 0


def test_unit_of_zero_is_zero():
    assert unit(np.zeros(2)) == pytest.approx([0.0, 0.0])
