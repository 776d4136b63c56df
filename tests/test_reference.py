"""Reference shortest path against hand-computed answers (tangent segments and arcs)."""

import json
import math
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from vplane_mj.geometry import cache, reference
from vplane_mj.geometry.reference import ReferencePath, shortest_path, shortest_path_length, world_key
from vplane_mj.scenario import load_scenario, parse_scenario

RADIUS = 0.11  # vplane_mj.robots.facts.robot_radius_m(), fixed here so the hand values are explicit
PAPER = ("paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape")


def scenario(obstacles="", start=(2.0, 5.0), goal=(8.0, 5.0), size=(10.0, 10.0), name="ref"):
    text = f"""
format = 1
name = "{name}"
[world]
size = [{size[0]}, {size[1]}]
{obstacles}
[robot]
start = [{start[0]}, {start[1]}]
goal = [{goal[0]}, {goal[1]}]
"""
    return parse_scenario(text, "<test>")


def wall(x0, y0, x1, y1, thickness=0.1):
    return f"""
[[world.obstacles]]
kind = "wall"
from = [{x0}, {y0}]
to = [{x1}, {y1}]
thickness = {thickness}
"""


def tangent_and_arc(point, centre, r, leave_angle):
    """Tangent length from `point` to the circle (centre, r) plus the arc, going over the top,
    from the tangent point clockwise to the point at angle `leave_angle`."""
    dx, dy = point[0] - centre[0], point[1] - centre[1]
    d = math.hypot(dx, dy)
    touch = (math.atan2(dy, dx) - math.acos(r / d)) % (2 * math.pi)
    return math.sqrt(d * d - r * r) + r * (touch - leave_angle)


def assert_path_is_clear(sc, ref, radius=RADIUS):
    from vplane_mj.geometry.shapes import scene_footprints

    fp = scene_footprints(sc.world.obstacles, sc.world.size)
    pts = np.concatenate(
        [np.linspace(a, b, 200) for a, b in zip(ref.points[:-1], ref.points[1:], strict=True)]
    )
    assert fp.distance(pts).min() >= radius - 1e-3  # samples every cell/2: a chord may dip
    assert ref.points[0] == pytest.approx(sc.robot.start) and ref.points[-1] == pytest.approx(sc.robot.goal)
    seg = np.diff(ref.points, axis=0)
    assert ref.length_m == pytest.approx(float(np.hypot(seg[:, 0], seg[:, 1]).sum()))


def test_empty_arena_is_the_straight_line():
    sc = scenario(start=(1.0, 1.0), goal=(8.5, 7.0))
    ref = shortest_path(sc, RADIUS)
    assert isinstance(ref, ReferencePath)
    assert ref.length_m == pytest.approx(math.hypot(7.5, 6.0), abs=1e-6)
    assert len(ref.points) == 2


def test_wall_with_a_gap_at_the_top_goes_round_its_inflated_end():
    # Wall x in [4.95, 5.05], y in [0, 8]; the gap is between y = 8 and the border at 10.
    sc = scenario(wall(5.0, 0.0, 5.0, 8.0))
    ref = shortest_path(sc, RADIUS)
    # Start -> tangent to the circle of radius r round corner (4.95, 8) -> arc to its top,
    # straight 0.1 m along y = 8 + r, arc round (5.05, 8), tangent to the goal (mirror image).
    half = tangent_and_arc((2.0, 5.0), (4.95, 8.0), RADIUS, math.pi / 2)
    hand = 2 * half + 0.1
    assert hand == pytest.approx(2 * math.hypot(3.0, 3.0 + RADIUS), rel=0.01)  # sanity: ~ via the gap corner
    assert ref.length_m == pytest.approx(hand, rel=0.01)
    assert ref.length_m >= hand - 1e-6  # never shorter than the true optimum
    assert_path_is_clear(sc, ref)


def test_cylinder_on_the_line_matches_tangents_plus_arc():
    cyl = '[[world.obstacles]]\nkind = "cylinder"\ncenter = [5.0, 5.0]\nradius = 1.0\n'
    sc = scenario(cyl)
    ref = shortest_path(sc, RADIUS)
    big, d = 1.0 + RADIUS, 3.0
    hand = 2 * math.sqrt(d * d - big * big) + big * (math.pi - 2 * math.acos(big / d))
    assert ref.length_m == pytest.approx(hand, rel=0.01)
    assert ref.length_m >= hand - 1e-6
    assert_path_is_clear(sc, ref)


@pytest.mark.parametrize("cyl_radius", [0.3, 2.0])
def test_cylinder_off_the_line_is_passed_on_its_far_side(cyl_radius):
    # Centre 0.2 m above the line y = 5: the shortest way passes below the inflated disc.
    centre, start, goal = (5.0, 5.2), (1.0, 5.0), (9.0, 5.0)
    cyl = f'[[world.obstacles]]\nkind = "cylinder"\ncenter = [5.0, 5.2]\nradius = {cyl_radius}\n'
    sc = scenario(cyl, start=start, goal=goal)
    big = cyl_radius + RADIUS
    total, touch = 0.0, []
    for point, side in ((start, 1), (goal, -1)):
        d = math.dist(point, centre)
        total += math.sqrt(d * d - big * big)
        touch.append(math.atan2(point[1] - centre[1], point[0] - centre[0]) + side * math.acos(big / d))
    hand = total + big * ((touch[1] - touch[0]) % (2 * math.pi))  # counter-clockwise along the bottom
    ref = shortest_path(sc, RADIUS)
    assert ref.length_m == pytest.approx(hand, rel=0.01)
    assert ref.length_m >= hand - 1e-6
    assert max(p[1] for p in ref.points) <= 5.0 + 1e-9  # below the line, on the far side from the centre
    assert_path_is_clear(sc, ref)


def test_enclosed_goal_has_no_path():
    box = (
        wall(7.0, 4.0, 9.0, 4.0)
        + wall(9.0, 4.0, 9.0, 6.0)
        + wall(9.0, 6.0, 7.0, 6.0)
        + wall(7.0, 6.0, 7.0, 4.0)
    )
    sc = scenario(box)
    assert shortest_path(sc, RADIUS) is None
    assert shortest_path_length(sc, RADIUS) is None


def test_gap_narrower_than_the_robot_is_closed():
    # Two walls leave a 0.2 m gap (< 2 * 0.11 robot diameter once the wall thickness is inflated).
    walls = wall(5.0, 0.0, 5.0, 4.9) + wall(5.0, 5.1, 5.0, 10.0)
    assert shortest_path(scenario(walls), RADIUS) is None
    # With a 0.4 m gap (0.3 m between the wall faces' ends > 0.22) the robot passes.
    walls = wall(5.0, 0.0, 5.0, 4.8) + wall(5.0, 5.2, 5.0, 10.0)
    ref = shortest_path(scenario(walls), RADIUS)
    assert ref is not None and ref.length_m == pytest.approx(6.0, rel=0.01)


@pytest.mark.parametrize("name", PAPER)
def test_paper_scenarios_have_a_reasonable_path(name):
    sc = load_scenario(name)
    straight = math.dist(sc.robot.start, sc.robot.goal)
    ref = shortest_path(sc, RADIUS)
    assert ref is not None
    assert straight - 1e-9 <= ref.length_m <= 1.5 * straight
    assert_path_is_clear(sc, ref)
    if name == "paper_c_escape":
        assert ref.length_m > 1.2 * straight  # the start is at the cup's mouth: out and round an arm


def test_a_winding_way_through_two_walls():
    walls = wall(3.0, 0.0, 3.0, 8.0) + wall(7.0, 2.0, 7.0, 10.0)
    sc = scenario(walls, start=(1.0, 1.0), goal=(9.0, 9.0))
    ref = shortest_path(sc, RADIUS)
    assert ref is not None and ref.length_m > math.dist((1, 1), (9, 9))
    assert_path_is_clear(sc, ref)


def test_the_key_is_the_world_alone():
    base = load_scenario("paper_c_escape")
    same_world = load_scenario(
        "paper_c_escape",
        ["planner.name=bug2", "run.seed=7", "sensors.noise_std=0.1", "robot.goal_tolerance=0.3"],
    )
    assert world_key(base, RADIUS) == world_key(same_world, RADIUS)
    for other in (
        load_scenario("paper_c_escape", ["world.obstacles[0].yaw_deg=1"]),
        load_scenario("paper_c_escape", ["robot.start=[4.3, 5.2]"]),
        load_scenario("paper_c_escape", ["robot.goal=[8.8, 5.3]"]),
        load_scenario("paper_c_escape", ["world.border=false"]),
    ):
        assert world_key(other, RADIUS) != world_key(base, RADIUS)
    assert world_key(base, RADIUS + 0.01) != world_key(base, RADIUS)


def test_the_length_is_computed_once_and_read_back_from_disk(monkeypatch, tmp_path):
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path))
    monkeypatch.setattr(reference, "_LENGTHS", {})
    sc = load_scenario("paper_c_escape")
    first = shortest_path_length(sc, RADIUS)
    assert first == pytest.approx(shortest_path(sc, RADIUS).length_m)
    assert len(list((tmp_path / "reference").glob("*.json"))) == 1

    def fail(*args):
        raise AssertionError("computed again")

    monkeypatch.setattr(reference, "shortest_path", fail)
    # another planner and seed, in memory ...
    assert (
        shortest_path_length(load_scenario("paper_c_escape", ["planner.name=apf", "run.seed=3"]), RADIUS)
        == first
    )
    monkeypatch.setattr(reference, "_LENGTHS", {})  # ... and from disk, as a new process would
    assert shortest_path_length(sc, RADIUS) == first


def test_a_damaged_or_unwritable_cache_only_costs_a_computation(monkeypatch, tmp_path):
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path))
    monkeypatch.setattr(reference, "_LENGTHS", {})
    sc = scenario(wall(5.0, 2.0, 5.0, 8.0))
    expected = shortest_path(sc, RADIUS).length_m
    shortest_path_length(sc, RADIUS)
    (entry,) = (tmp_path / "reference").glob("*.json")
    entry.write_text(entry.read_text()[:20])  # torn
    monkeypatch.setattr(reference, "_LENGTHS", {})
    assert shortest_path_length(sc, RADIUS) == pytest.approx(expected)
    assert json.loads(entry.read_text())["value"] == pytest.approx(expected)  # and stored whole again
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv(cache.CACHE_ENV, str(blocker / "cache"))  # below a file: cannot exist
    monkeypatch.setattr(reference, "_LENGTHS", {})
    assert shortest_path_length(sc, RADIUS) == pytest.approx(expected)


def _slow_square(log: str) -> int:
    def compute():
        with open(log, "a") as stream:
            stream.write("computed\n")
        time.sleep(0.3)
        return 49

    return cache.cached("test", {"x": 7}, compute)


def test_processes_that_miss_the_same_key_compute_it_once(monkeypatch, tmp_path):
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path / "cache"))
    log = tmp_path / "log"
    with ProcessPoolExecutor(4) as pool:
        values = list(pool.map(_slow_square, [str(log)] * 4))
    assert values == [49] * 4
    assert log.read_text().splitlines() == ["computed"]
