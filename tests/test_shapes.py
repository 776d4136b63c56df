"""Obstacle footprints and distances against hand-computed points (docs/interface.md section 1)."""

import math

import numpy as np
import pytest

from vplane_mj import shapes


def distance(pieces, point):
    return float(shapes.Footprints(pieces).distance(np.array([point]))[0])


def test_box_rotated_by_90_degrees_swaps_its_extents():
    box = shapes.Box(center=(2.0, 3.0), size=(2.0, 0.5), yaw=math.pi / 2)
    (rect,) = box.footprint()
    # After a 90 degree turn the long side runs along y: the point 0.9 m above is inside.
    assert distance([rect], (2.0, 3.9)) < 0
    assert distance([rect], (2.9, 3.0)) == pytest.approx(0.9 - 0.25)


def test_cup_pieces_match_the_contract_table():
    cup = shapes.Cup(center=(0.0, 0.0), width=1.6, depth=1.2, thickness=0.1)
    back, left, right = cup.footprint()
    # back wall x in [depth/2 - t, depth/2] = [0.5, 0.6], y in [-0.8, 0.8]
    assert back.center == pytest.approx((0.55, 0.0)) and back.half == pytest.approx((0.05, 0.8))
    # arms x in [-0.6, 0.6], y in [0.7, 0.8] and [-0.8, -0.7]
    assert left.center == pytest.approx((0.0, 0.75)) and left.half == pytest.approx((0.6, 0.05))
    assert right.center == pytest.approx((0.0, -0.75))


def test_cup_mouth_faces_local_minus_x_after_rotation():
    cup = shapes.Cup(center=(5.0, 5.0), width=1.6, depth=1.2, yaw=math.pi / 2, thickness=0.1)
    pieces = cup.footprint()
    # Rotated by 90 degrees the back wall is at +y and the mouth opens toward -y.
    assert distance(pieces, (5.0, 5.55)) < 0
    assert distance(pieces, (5.0, 4.45)) > 0.3  # the open mouth: nothing near
    assert distance(pieces, (5.0, 5.0)) == pytest.approx(0.5)  # the cup's centre to the back wall


def test_h_shape_crossbar_and_posts():
    h = shapes.HShape(center=(0.0, 0.0), length=1.6, width=1.0, thickness=0.1)
    pieces = h.footprint()
    assert distance(pieces, (0.0, 0.0)) < 0  # on the crossbar
    assert distance(pieces, (0.8, 0.45)) <= 0  # end of the +y post
    assert distance(pieces, (-0.4, 0.0)) == pytest.approx(0.35)  # inside the -x cup
    assert distance(pieces, (0.4, 0.0)) == pytest.approx(0.35)  # inside the +x cup


def test_wall_has_no_end_caps():
    wall = shapes.Wall(start=(0.0, 0.0), end=(2.0, 0.0), thickness=0.2)
    assert distance(wall.footprint(), (2.1, 0.0)) == pytest.approx(0.1)
    assert distance(wall.footprint(), (1.0, 0.5)) == pytest.approx(0.4)
    diagonal = shapes.Wall(start=(0.0, 0.0), end=(1.0, 1.0), thickness=0.1)
    assert distance(diagonal.footprint(), (0.0, 1.0)) == pytest.approx(math.sqrt(0.5) - 0.05)


def test_cylinder_and_corner_distance():
    disc = shapes.Cylinder(center=(1.0, 1.0), radius=0.5).footprint()
    assert distance(disc, (1.0, 2.0)) == pytest.approx(0.5)
    square = shapes.Box(center=(0.0, 0.0), size=(2.0, 2.0)).footprint()
    assert distance(square, (2.0, 2.0)) == pytest.approx(math.sqrt(2.0))
    assert distance(square, (0.0, 0.5)) == pytest.approx(-0.5)


def test_border_encloses_the_arena():
    border = shapes.border_footprint((4.0, 3.0))
    field = shapes.Footprints(border)
    inside = np.array([[2.0, 1.5], [0.5, 0.5], [3.9, 2.9]])
    assert field.distance(inside) == pytest.approx([1.5, 0.5, 0.1])
    outside = np.array([[-0.05, 1.5], [2.0, 3.05], [4.05, -0.05]])
    assert np.all(field.distance(outside) < 0)


def test_empty_scene_is_infinitely_far():
    field = shapes.scene_footprints([])
    assert len(field) == 0
    assert np.isinf(field.distance(np.zeros((3, 2)))).all()
