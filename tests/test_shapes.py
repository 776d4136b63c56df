"""Obstacle footprints and distances against hand-computed points (docs/interface.md section 1)."""

import math

import numpy as np
import pytest

from vplane_mj.geometry import shapes


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


JACKAL_OUTLINE = np.array([(-0.254, -0.215), (0.254, -0.215), (0.254, 0.215), (-0.254, 0.215)])


def _world_outline(outline, pose):
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return outline @ np.array([[c, s], [-s, c]]) + pose[:2]


def _inside_outline(polygon, points):
    edges = np.roll(polygon, -1, axis=0) - polygon
    rel = points[:, None, :] - polygon[None]
    return ((edges[None, :, 0] * rel[..., 1] - edges[None, :, 1] * rel[..., 0]) >= 0).all(axis=1)


def _random_pieces(rng, spread):
    pieces = []
    for _ in range(rng.integers(1, 5)):
        centre = tuple(rng.uniform(-spread, spread, 2))
        if rng.random() < 0.5:
            pieces.append(shapes.Rect(centre, tuple(rng.uniform(0.02, 0.6, 2)), rng.uniform(-3, 3)))
        else:
            pieces.append(shapes.Disc(centre, rng.uniform(0.03, 0.4)))
    return pieces


def test_a_rectangle_beside_a_box_is_as_far_as_their_facing_sides():
    footprints = shapes.Footprints([shapes.Rect((1.0, 0.0), (0.1, 0.5))])
    # The outline's front side is at x = 0.254; the box's near side at x = 0.9.
    at_rest = footprints.outline_distance(JACKAL_OUTLINE, np.array([[0.0, 0.0, 0.0]]))
    assert at_rest[0] == pytest.approx(0.9 - 0.254)
    # Turned 90 degrees, its side (0.215 from the centre) faces the box instead.
    turned = footprints.outline_distance(JACKAL_OUTLINE, np.array([[0.0, 0.0, math.pi / 2]]))
    assert turned[0] == pytest.approx(0.9 - 0.215)
    # Pushed 0.1 m into the box, it overlaps by 0.1 m.
    inside = footprints.outline_distance(JACKAL_OUTLINE, np.array([[0.746, 0.0, 0.0]]))
    assert inside[0] == pytest.approx(-0.1)


def test_a_disc_beside_a_rectangle_is_as_far_as_its_nearest_corner():
    footprints = shapes.Footprints([shapes.Disc((1.0, 1.0), 0.2)])
    corner = np.hypot(1.0 - 0.254, 1.0 - 0.215)
    distance = footprints.outline_distance(JACKAL_OUTLINE, np.array([[0.0, 0.0, 0.0]]))
    assert distance[0] == pytest.approx(corner - 0.2)


def test_outline_distance_matches_the_sampled_boundary_on_random_scenes():
    rng = np.random.default_rng(3)
    side = np.linspace(0.0, 1.0, 300)[:, None]
    for _ in range(200):
        footprints = shapes.Footprints(_random_pieces(rng, 1.5))
        pose = np.array([*rng.uniform(-0.5, 0.5, 2), rng.uniform(-3, 3)])
        exact = footprints.outline_distance(JACKAL_OUTLINE, pose[None])[0]
        world = _world_outline(JACKAL_OUTLINE, pose)
        boundary = np.vstack([a + (b - a) * side for a, b in zip(world, np.roll(world, -1, 0), strict=True)])
        sampled = footprints.distance(boundary).min()
        if exact > 0:  # parted: the nearest outline point lies on the sampled boundary
            assert exact == pytest.approx(sampled, abs=2e-3)
        else:  # overlapping: some point of the outline's inside lies in an obstacle
            grid = np.stack(np.meshgrid(*2 * [np.linspace(-0.4, 0.4, 161)]), -1).reshape(-1, 2) + pose[:2]
            assert (_inside_outline(world, grid) & (footprints.distance(grid) < 0)).any()


def test_outline_distance_of_many_poses_equals_each_pose_alone():
    rng = np.random.default_rng(4)
    footprints = shapes.Footprints(_random_pieces(rng, 2.0) + list(shapes.border_footprint((4.0, 4.0))))
    poses = np.column_stack((rng.uniform(0, 4, 50), rng.uniform(0, 4, 50), rng.uniform(-3, 3, 50)))
    together = footprints.outline_distance(JACKAL_OUTLINE, poses)
    alone = [footprints.outline_distance(JACKAL_OUTLINE, pose[None])[0] for pose in poses]
    np.testing.assert_allclose(together, alone)


def test_outline_distance_among_many_pieces_is_the_least_over_each_piece_alone():
    # Only the pieces the bounds leave are measured: none that could be the nearest is left out,
    # bit for bit, for an outline about its centre and one about an origin near its back.
    rng = np.random.default_rng(5)
    pieces = [shapes.Disc(tuple(rng.uniform(0, 4, 2)), rng.uniform(0.03, 0.2)) for _ in range(120)]
    pieces += [
        shapes.Rect(tuple(rng.uniform(0, 4, 2)), tuple(rng.uniform(0.02, 0.3, 2)), rng.uniform(-3, 3))
        for _ in range(30)
    ]
    footprints = shapes.Footprints(pieces)
    alone = [shapes.Footprints([piece]) for piece in pieces]
    poses = np.column_stack((rng.uniform(0, 4, 300), rng.uniform(0, 4, 300), rng.uniform(-3, 3, 300)))
    for outline in (JACKAL_OUTLINE, JACKAL_OUTLINE + np.array([0.2, 0.05])):
        each = np.min([piece.outline_distance(outline, poses) for piece in alone], axis=0)
        np.testing.assert_array_equal(footprints.outline_distance(outline, poses), each)
