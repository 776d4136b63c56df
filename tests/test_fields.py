"""FIRAS attraction and repulsion (paper eqs. 2-6): gradients, directions, safety at zero distance."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from vplane_mj.planning.motion import fields

GOAL = np.array([3.0, -1.0])
OBSTACLES = np.array([[0.5, 0.2], [0.6, -0.4], [-0.3, 0.5]])


def numeric_gradient(potential, x, h=1e-6):
    grad = np.zeros(2)
    for i in range(2):
        step = np.zeros(2)
        step[i] = h
        grad[i] = (potential(x + step) - potential(x - step)) / (2 * h)
    return grad


@pytest.mark.parametrize("point", [(2.5, -0.8), (0.0, 0.0), (-4.0, 3.0)])
def test_attractive_force_is_minus_gradient_of_its_potential(point):
    x = np.array(point)
    grad = numeric_gradient(lambda p: fields.attractive_potential(p, GOAL, 0.7, 1.0), x)
    assert fields.attractive_force(x, GOAL, 0.7, 1.0) == pytest.approx(-grad, abs=1e-5)


def test_attractive_potential_is_continuous_at_the_switch_radius():
    inside = GOAL + np.array([1.0 - 1e-9, 0.0])
    outside = GOAL + np.array([1.0 + 1e-9, 0.0])
    a = fields.attractive_potential(inside, GOAL, 0.5, 1.0)
    b = fields.attractive_potential(outside, GOAL, 0.5, 1.0)
    assert a == pytest.approx(b, abs=1e-6)


def test_attractive_force_is_bounded_far_away_and_points_to_the_goal():
    far = np.array([100.0, -1.0])
    force = fields.attractive_force(far, GOAL, 0.5, 1.0)
    assert np.linalg.norm(force) == pytest.approx(2 * 0.5 * 1.0)
    assert force[0] < 0 and abs(force[1]) < 1e-12


@pytest.mark.parametrize("point", [(0.0, 0.0), (0.3, 0.1), (1.0, 1.0)])
def test_repulsive_force_is_minus_gradient_of_its_potential(point):
    x = np.array(point)
    grad = numeric_gradient(lambda p: fields.repulsive_potential(p, OBSTACLES, 0.02, 0.8), x)
    assert fields.repulsive_force(x, OBSTACLES, 0.02, 0.8) == pytest.approx(-grad, rel=1e-4, abs=1e-7)


def test_repulsion_points_away_and_vanishes_beyond_influence():
    obstacle = np.array([[1.0, 0.0]])
    near = fields.repulsive_force(np.array([0.5, 0.0]), obstacle, 0.02, 0.8)
    assert near[0] < 0 and near[1] == 0
    assert fields.repulsive_force(np.array([0.1, 0.0]), obstacle, 0.02, 0.8) == pytest.approx([0, 0])
    assert fields.repulsive_force(np.zeros(2), np.empty((0, 2)), 0.02, 0.8) == pytest.approx([0, 0])


@given(st.floats(min_value=0.0, max_value=1e-3), st.floats(min_value=0, max_value=6.3))
def test_no_inf_or_nan_as_a_distance_goes_to_zero(distance, angle):
    obstacle = np.array([[1.0, 1.0]])
    x = obstacle[0] + distance * np.array([np.cos(angle), np.sin(angle)])
    force = fields.repulsive_force(x, obstacle, 0.02, 0.8)
    assert np.all(np.isfinite(force))
    assert np.isfinite(fields.repulsive_potential(x, obstacle, 0.02, 0.8))
    assert np.all(np.isfinite(fields.attractive_force(x, x, 0.5, 1.0)))
