"""Moving obstacles in a run's views: the MCAP log (`/world/moving`, `/tracks`), its replay, the
render and the video."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from vplane_mj.logs.reader import iter_messages, read_log
from vplane_mj.logs.replay import disagreements, obstacle_distances, summarize, track_from_log
from vplane_mj.logs.scene import TRACK_ARROW_S
from vplane_mj.logs.timeline import timeline_from_log
from vplane_mj.logs.writer import MOVING_PERIOD_S, MOVING_TOPIC, TRACKS_TOPIC, McapLog, time_ns
from vplane_mj.planning.protocol.types import Decision
from vplane_mj.scenario import parse_scenario
from vplane_mj.sim.loop import Tick, run_scenario
from vplane_mj.sim.sensors import scan_bearings
from vplane_mj.sim.world import OBSTACLE_HEIGHT_M, top_view_extent
from vplane_mj.viz import palette
from vplane_mj.viz.render import render_top_view
from vplane_mj.viz.video import FrameCanvas

TWO_MOVING = """
format = 1
name = "two_moving"
[world]
size = [6.0, 4.0]
[[world.obstacles]]
kind = "box"
center = [2.0, 0.7]
size = [0.6, 0.6]
[[world.obstacles]]
kind = "cylinder"
radius = 0.3
[world.obstacles.motion]
keyframes = [[0, 3.2, 0.4], [4, 3.2, 3.6]]
interpolation = "linear"
[[world.obstacles]]
kind = "box"
size = [0.5, 0.3]
yaw_deg = 30
[world.obstacles.motion]
keyframes = [[0, 4.6, 3.4], [3, 4.6, 1.0], [6, 4.6, 3.4]]
[robot]
start = [0.6, 2.0]
goal = [5.4, 2.0]
[run]
time_limit_s = 8.0
"""
"""A static box (obstacle 0), a cylinder crossing the robot's way on a loop that jumps back
(obstacle 1) and a box on a closed spline (obstacle 2)."""


class Places:
    """Keeps where each tick saw the moving obstacles."""

    def __init__(self):
        self.times: list[float] = []
        self.places: list[np.ndarray] = []

    def on_tick(self, tick):
        self.times.append(tick.time_s)
        self.places.append(tick.obstacles)

    def on_event(self, time_s, event):
        pass


@dataclasses.dataclass(frozen=True)
class StandInTrack:
    """What the log reads of a tracker's track."""

    track_id: int
    position: np.ndarray
    velocity: np.ndarray
    radius_m: float
    moving: bool
    position_std_m: float = 0.05


def logged_run(path, text: str, overrides=()):
    scenario = parse_scenario(text, "two_moving.toml", overrides=list(overrides))
    log = McapLog(path, scenario, scan_bearings(scenario), {})
    places = Places()
    result = run_scenario(scenario, observers=(log, places))
    log.close(result.summary.to_dict())
    return scenario, result, places


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    path = tmp_path_factory.mktemp("moving") / "run.mcap"
    scenario, result, places = logged_run(path, TWO_MOVING)
    return {
        "scenario": scenario,
        "path": path,
        "result": result,
        "places": places,
        "contents": read_log(path),
    }


def motions_at(scenario, times_s: np.ndarray) -> np.ndarray:
    """Where the motions put the moving obstacles at these run times (N, count, 2; m)."""
    return np.stack([m.motion.position(times_s) for m in scenario.world.moving], axis=1)


def test_world_moving_holds_every_obstacle_where_it_stands_at_every_tick(run):
    scenario, contents, places = run["scenario"], run["contents"], run["places"]
    assert contents.topics[MOVING_TOPIC] == ("foxglove.SceneUpdate", len(places.times))
    times_s = contents.obstacle_times_ns / 1e9
    assert contents.obstacle_times_ns.tolist() == [time_ns(t) for t in places.times]
    assert np.diff(times_s).max() <= MOVING_PERIOD_S + 1e-9  # at least 10 times a simulated second
    np.testing.assert_array_equal(contents.obstacle_places, np.array(places.places))  # the ticks' own
    # each where its motion puts it at the tick, or one physics step before (the step the run made)
    offsets = [
        np.hypot(*(contents.obstacle_places - motions_at(scenario, times_s - step)).transpose(2, 0, 1))
        for step in (0.0, scenario.run.physics_dt_s)
    ]
    assert np.minimum(*offsets).max() < 1e-9
    assert np.ptp(contents.obstacle_places[:, 0, 1]) > 2.0  # the cylinder went places
    for update in iter_messages(run["path"], (MOVING_TOPIC,)):
        cylinder, box = update.message.entities
        assert (cylinder.id, box.id) == ("obstacle_1", "obstacle_2")
        assert not cylinder.cubes and cylinder.cylinders[0].size.x == pytest.approx(0.6)
        (cube,) = box.cubes
        assert (cube.size.x, cube.size.y, cube.size.z) == pytest.approx((0.5, 0.3, OBSTACLE_HEIGHT_M))
        q = cube.pose.orientation
        assert math.degrees(2 * math.atan2(q.z, q.w)) == pytest.approx(30.0)


def test_world_holds_the_static_obstacles_only(run):
    (world,) = iter_messages(run["path"], ("/world",))
    obstacles = [entity for entity in world.message.entities if entity.id.startswith("obstacle_")]
    assert [entity.id for entity in obstacles] == ["obstacle_0"]
    (cube,) = obstacles[0].cubes
    assert (cube.pose.position.x, cube.pose.position.y) == (2.0, 0.7)


def test_ticks_far_apart_get_the_motions_places_between_them(tmp_path):
    scenario, _, places = logged_run(
        tmp_path / "slow.mcap", TWO_MOVING, ["run.control_hz=4", "run.time_limit_s=2"]
    )
    contents = read_log(tmp_path / "slow.mcap")
    times_s = contents.obstacle_times_ns / 1e9
    assert np.diff(times_s).max() <= MOVING_PERIOD_S + 1e-9 and len(times_s) > 2 * len(places.times)
    ticks = np.isin(contents.obstacle_times_ns, [time_ns(t) for t in places.times])
    np.testing.assert_array_equal(contents.obstacle_places[ticks], np.array(places.places))
    between = motions_at(scenario, times_s[~ticks])
    np.testing.assert_allclose(contents.obstacle_places[~ticks], between, rtol=0, atol=1e-8)  # times in ns


def test_tracks_are_drawn_and_vanish(tmp_path):
    scenario = parse_scenario(TWO_MOVING, "two_moving.toml")
    path = tmp_path / "tracks.mcap"
    log = McapLog(path, scenario, scan_bearings(scenario), {})
    ranges = np.full(len(scan_bearings(scenario)), np.nan)
    walker = StandInTrack(7, np.array([3.0, 2.0]), np.array([0.0, 1.2]), 0.3, True)
    post = StandInTrack(2, np.array([1.0, 3.0]), np.zeros(2), 0.2, False)
    for k, tracks in enumerate([(), (walker, post), (walker,), ()]):
        decision = Decision(force=np.zeros(2), mode="normal")
        log.on_tick(
            Tick(0.05 * k, np.array([1.0, 1.0]), 0.0, 0.0, ranges, decision, (0.0, 0.0), tracks=tracks)
        )
    log.close()
    updates = list(iter_messages(path, (TRACKS_TOPIC,)))
    assert [u.log_time_ns for u in updates] == [time_ns(0.05), time_ns(0.1), time_ns(0.15)]
    first, second, last = (u.message for u in updates)
    assert [e.id for e in first.entities] == ["track_7"] and not first.deletions  # the post stands
    (arrow,) = first.entities[0].arrows
    assert arrow.shaft_length + arrow.head_length == pytest.approx(1.2 * TRACK_ARROW_S)
    assert (arrow.pose.position.x, arrow.pose.position.y) == (3.0, 2.0)
    assert (
        first.entities[0].cylinders[0].size.x == pytest.approx(0.6)
        and not first.entities[0].lines
        and first.entities[0].texts[0].text == "7"
    )
    assert [e.id for e in second.entities] == ["track_7"] and not second.deletions
    assert [d.id for d in last.deletions] == ["track_7"] and not last.entities


def test_the_replay_counts_the_moving_obstacles(run):
    contents, scenario, stored = run["contents"], run["scenario"], run["result"].summary.to_dict()
    recomputed = summarize(contents, scenario)
    assert disagreements(recomputed, stored) == []
    moving = recomputed["min_clearance_moving_m"]
    assert moving == pytest.approx(stored["min_clearance_moving_m"], abs=0.01)
    assert recomputed["min_clearance_m"] == moving  # the cylinder came closer than anything static
    track = track_from_log(run["path"], contents)
    assert track.obstacle_places is not None and len(track.obstacle_places) == len(track.positions)
    np.testing.assert_array_equal(track.obstacle_places, contents.obstacle_places)  # one at each pose


def metres_per_pixel(scenario, image: np.ndarray) -> tuple[float, np.ndarray]:
    """The render's scale (m a pixel) and the point (m) at its top left corner."""
    width_m, height_m = top_view_extent(scenario.world.size)
    margin = (width_m - scenario.world.size[0]) / 2
    return height_m / image.shape[0], np.array([-margin, height_m - margin])


def to_metres(scenario, image: np.ndarray, rows: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """The points (m) at the centres of the render's pixels (row, column)."""
    scale, corner = metres_per_pixel(scenario, image)
    return corner + np.column_stack((columns + 0.5, -(rows + 0.5))) * scale


def to_pixel(scenario, image: np.ndarray, xy: np.ndarray) -> tuple[int, int]:
    """The (row, column) of the render's pixel at the point xy (m)."""
    scale, corner = metres_per_pixel(scenario, image)
    column, row = (xy - corner) / scale * (1, -1)
    return int(row), int(column)


def nearest(points: np.ndarray, others: np.ndarray) -> np.ndarray:
    """The distance (m) from each point (P, 2) to the nearest of `others` (N, 2)."""
    return np.min([np.hypot(*(points - other).T) for other in others], axis=0)


def test_the_render_draws_traces_where_the_obstacles_went_and_leaves_the_rest_alone(run):
    scenario, track = run["scenario"], run["result"].track()
    still = dataclasses.replace(scenario, world=dataclasses.replace(scenario.world, moving=()))
    image = render_top_view(scenario, track).astype(int)
    static_image = render_top_view(still, dataclasses.replace(track, obstacle_places=None)).astype(int)
    assert image.shape == static_image.shape
    differs = np.any(image != static_image, axis=2)
    arena_px = round(image.shape[0] * np.divide(*top_view_extent(scenario.world.size)))
    assert differs[:, arena_px:].any()  # the legend names the marks
    rows, columns = np.nonzero(differs[:, :arena_px])
    points = to_metres(scenario, image, rows, columns)
    places, positions = track.obstacle_places, track.positions
    closest = np.argmin(obstacle_distances(scenario.world.moving, positions, places), axis=0)
    allowed = np.full(len(points), np.inf)
    for k, tick in enumerate(closest):  # the obstacle's places (traces, shape, outline), its closest approach
        allowed = np.minimum(allowed, nearest(points, places[:, k]) - 0.45)
        robot = positions[tick]
        line = robot + np.linspace(0.0, 1.0, 50)[:, None] * (places[tick, k] - robot)
        allowed = np.minimum(allowed, nearest(points, line) - 0.1)
    assert len(points) > 500 and (allowed <= 0).all()  # the static world's picture is untouched elsewhere
    cylinder = places[:, 0]
    away = (  # where the cylinder's trace shows: off its end, its closest approach and the path
        (np.hypot(*(cylinder - cylinder[-1]).T) > 0.5)
        & (np.hypot(*(cylinder - cylinder[closest[0]]).T) > 0.5)
        & (nearest(cylinder, positions) > 0.2)
    )
    assert away.sum() > 10
    for xy in cylinder[away]:
        row, column = to_pixel(scenario, image, xy)
        red, green, blue = image[row, column]
        assert differs[row, column] and red == green == blue, xy  # the obstacles' grey, faded or not


OBSTACLE_GREY = np.round(np.array(palette.MOVING_OBSTACLE.rgba[:3]) * 255)
"""The video's moving obstacles' colour."""


def test_the_video_moves_the_obstacles(run):
    contents, scenario = run["contents"], run["scenario"]
    timeline = timeline_from_log(run["path"], contents)
    np.testing.assert_array_equal(timeline.obstacles, contents.obstacle_places)
    canvas = FrameCanvas(scenario, timeline, 480, 1.0)
    width, height = canvas.size
    frames, centres = [], []
    for t in (0.5, 2.5):
        rgba = np.frombuffer(canvas.frame(t), np.uint8).reshape(height, width, 4)
        frames.append(np.abs(rgba[..., :3].astype(int) - OBSTACLE_GREY).sum(axis=2) < 30)  # obstacle pixels
        column, row = canvas.axes.transData.transform(timeline.obstacles[timeline.index_at(t), 0])
        centres.append((round(height - row), round(column)))
    (first, second), (then, later) = frames, centres
    assert first[then] and not first[later] and second[later] and not second[then]  # the cylinder moved
    assert (first != second).sum() > 200
