"""The MCAP log (docs/interface.md section 4): a real short run written, read back and checked."""

from __future__ import annotations

import importlib.util
import itertools
import json
import math
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap.records import Chunk
from mcap.stream_reader import StreamReader

from vplane_mj.geometry.polyline import distances_to_segment
from vplane_mj.logs.reader import iter_messages, read_log
from vplane_mj.logs.scene import ARROW_M_PER_UNIT, ARROW_MAX_M, PATH_ID
from vplane_mj.logs.writer import (
    EVENTS_JSON_SCHEMA,
    FLUSH_PERIOD_S,
    METADATA_NAME,
    METRICS_JSON_SCHEMA,
    PATH_TOLERANCE_M,
    RANGE_STEP_M,
    McapLog,
    time_ns,
)
from vplane_mj.planning.protocol.events import Event, EventKind
from vplane_mj.planning.protocol.types import Decision
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.scenario import load_scenario, parse_scenario
from vplane_mj.sim.loop import Tick, run_scenario
from vplane_mj.sim.sensors import scan_bearings
from vplane_mj.sim.world import OBSTACLE_HEIGHT_M

TIME_LIMIT_S = 12.0  # vplane detects the trap at ~5.5 s and finishes its escape at ~10.5 s

EXPECTED_SCHEMAS = {
    "/robot/pose": "foxglove.PoseInFrame",
    "/tf": "foxglove.FrameTransforms",
    "/scan": "foxglove.LaserScan",
    "/world": "foxglove.SceneUpdate",
    "/forces": "foxglove.SceneUpdate",
    "/virtual": "foxglove.SceneUpdate",
    "/path": "foxglove.SceneUpdate",
    "/events": "foxglove.Log",
}


class Recorder:
    """Keeps what the sonar and the planner produced at each tick, to compare with the log."""

    def __init__(self):
        self.ranges: list[np.ndarray] = []
        self.forces: list[np.ndarray] = []

    def on_tick(self, tick):
        self.ranges.append(np.array(tick.ranges, dtype=float))
        self.forces.append(np.array(tick.decision.force, dtype=float))

    def on_event(self, time_s, event):
        pass


def make_log(path: Path, scenario, metadata=None) -> McapLog:
    bearings = scan_bearings(scenario)
    return McapLog(path, scenario, bearings, metadata or {})


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    scenario = load_scenario("paper_c_escape", [f"run.time_limit_s={TIME_LIMIT_S}"])
    path = tmp_path_factory.mktemp("mcap") / "run.mcap"
    log = make_log(path, scenario, {"command": "pytest"})
    recorder = Recorder()
    result = run_scenario(scenario, observers=(log, recorder))
    log.close(result.summary.to_dict())
    return {
        "scenario": scenario,
        "path": path,
        "result": result,
        "recorder": recorder,
        "contents": read_log(path),
    }


def test_every_topic_with_its_schema(run):
    topics = run["contents"].topics
    for topic, schema in EXPECTED_SCHEMAS.items():
        assert topic in topics, topic
        assert topics[topic][0] == schema
        assert topics[topic][1] > 0
    assert "/metrics" in topics
    assert run["contents"].message_encodings["/metrics"] == "json"
    assert all(run["contents"].message_encodings[t] == "protobuf" for t in EXPECTED_SCHEMAS)
    assert run["contents"].complete


def test_one_pose_per_tick_in_simulated_nanoseconds(run):
    contents, result = run["contents"], run["result"]
    n = len(result.times) + 1  # every control tick, then the state the run ended in
    assert n > 100
    assert contents.topics["/robot/pose"][1] == n
    assert contents.topics["/tf"][1] == n
    assert contents.topics["/scan"][1] == n
    assert contents.topics["/forces"][1] == n
    assert contents.times_ns.dtype == np.int64
    assert np.all(np.diff(contents.times_ns) > 0)
    assert contents.times_ns.tolist()[:-1] == [round(t * 1e9) for t in result.times]
    assert contents.times_ns[-1] == round(result.summary.sim_time_s * 1e9)
    np.testing.assert_array_equal(contents.positions[:-1], result.positions)
    assert contents.positions[-1] == pytest.approx(result.track().final_pose[:2])
    assert np.all(np.isfinite(contents.yaws))
    assert contents.modes == [*result.modes, "finished"]


def test_pose_tf_and_message_timestamps_agree(run):
    poses = list(iter_messages(run["path"], ("/robot/pose",)))[:5]
    tfs = list(iter_messages(run["path"], ("/tf",)))[:5]
    for pose, tf in zip(poses, tfs, strict=True):
        stamp = pose.message.timestamp
        assert stamp.seconds * 10**9 + stamp.nanos == pose.log_time_ns == tf.log_time_ns
        assert pose.message.frame_id == "world"
        transform, follow = tf.message.transforms
        assert (transform.parent_frame_id, transform.child_frame_id) == ("world", "base_link")
        assert (follow.parent_frame_id, follow.child_frame_id) == ("world", "base_link_xy")
        assert follow.translation == transform.translation and follow.rotation.w == 1.0
        assert transform.translation.x == pose.message.pose.position.x
        q = pose.message.pose.orientation
        assert (q.x, q.y, q.z) == (0.0, 0.0, transform.rotation.z)
        assert math.isclose(q.z**2 + q.w**2, 1.0)
        assert pose.message.pose.position.z == 0.0
    first = poses[0].message.pose
    yaw = 2 * math.atan2(first.orientation.z, first.orientation.w)
    assert math.isclose(yaw, run["scenario"].robot.start_yaw, abs_tol=0.05)


def test_scan_has_nan_for_no_echo_and_the_ring_step(run):
    scans = list(iter_messages(run["path"], ("/scan",)))
    recorded = run["recorder"].ranges
    assert len(scans) == len(recorded)
    saw_nan = saw_echo = False
    for scan, ranges in zip(scans, recorded, strict=True):
        msg = scan.message
        assert msg.frame_id == "base_link"
        logged = np.array(msg.ranges)
        assert len(logged) == 16
        step = (msg.end_angle - msg.start_angle) / (len(logged) - 1)
        assert math.isclose(step, 2 * math.pi / 16)
        assert msg.start_angle == 0.0
        np.testing.assert_array_equal(np.isnan(logged), ~np.isfinite(ranges))
        echoes = np.isfinite(ranges)
        np.testing.assert_allclose(logged[echoes], ranges[echoes], rtol=0.0, atol=RANGE_STEP_M / 2)
        assert np.all(logged[echoes] / RANGE_STEP_M == np.round(logged[echoes] / RANGE_STEP_M))
        saw_nan |= bool(np.isnan(logged).any())
        saw_echo |= bool(np.isfinite(logged).any())
    assert saw_nan and saw_echo


def test_world_once_at_time_zero(run):
    scenario = run["scenario"]
    assert run["contents"].topics["/world"][1] == 1
    (world,) = iter_messages(run["path"], ("/world",))
    assert world.log_time_ns == 0
    entities = {entity.id: entity for entity in world.message.entities}
    robot = entities.pop("robot")  # drawn in the robot's frame, moving with /tf
    assert (robot.frame_id, robot.frame_locked) == ("base_link", True)
    (body,) = robot.cylinders
    assert math.isclose(body.size.x / 2, robot_radius_m()) and robot.arrows
    assert all(entity.frame_id == "world" for entity in entities.values())
    pieces = sum(len(ob.footprint()) for ob in scenario.world.obstacles)
    obstacles = [e for name, e in entities.items() if name.startswith("obstacle_")]
    assert len(obstacles) == len(scenario.world.obstacles)
    assert sum(len(e.cubes) + len(e.cylinders) for e in obstacles) == pieces
    assert all(cube.size.z == OBSTACLE_HEIGHT_M for e in obstacles for cube in e.cubes)
    assert scenario.world.border and len(entities["border"].cubes) == 4
    (goal,) = entities["goal"].cylinders
    assert math.isclose(goal.size.x / 2, scenario.robot.goal_tolerance)
    assert (goal.pose.position.x, goal.pose.position.y) == scenario.robot.goal
    assert "start" in entities


def test_metadata_holds_the_resolved_scenario_and_versions(run):
    scenario, metadata = run["scenario"], run["contents"].metadata
    info = metadata[METADATA_NAME]
    again = parse_scenario(info["scenario_toml"], "from-log.toml")
    assert again.name == scenario.name == info["scenario"]
    assert again.run.seed == scenario.run.seed == int(info["seed"])
    assert again.run.time_limit_s == TIME_LIMIT_S
    assert info["planner"] == scenario.planner == "vplane"
    for key in ("vplane_mj_version", "mujoco_version", "numpy_version", "foxglove_sdk_version"):
        assert info[key]
    assert info["command"] == "pytest"
    summary = run["contents"].summary
    assert summary == json.loads(json.dumps(run["result"].summary.to_dict()))


def test_events_as_text_and_as_data(run):
    events = run["contents"].events
    assert (events[0].time_s, events[0].kind) == (0.0, EventKind.RUN_STARTED)
    assert events[0].text == "run started: paper_c_escape, planner vplane, seed 0"
    detected = next(e for e in events if e.kind is EventKind.LOCAL_MINIMUM)
    assert 2.0 < detected.time_s < TIME_LIMIT_S and detected.text == "local minimum detected"
    started = next(e for e in events if e.kind is EventKind.ESCAPE_STARTED)
    assert set(started.data) == {"e1", "e2", "objective"}  # the points, as numbers
    logs = list(iter_messages(run["path"], ("/events",)))
    assert [(m.log_time_ns, m.message.name, m.message.message) for m in logs] == [
        (time_ns(e.time_s), str(e.kind), e.text) for e in events
    ]
    assert all(m.message.level == 2 for m in logs)  # INFO: no collision, nobody gave up


def test_virtual_objective_deleted_after_the_escape(run):
    events = run["contents"].events
    finished = next(e.time_s for e in events if e.kind is EventKind.ESCAPE_FINISHED)
    updates = list(iter_messages(run["path"], ("/virtual",)))
    times = [u.log_time_ns for u in updates]
    assert times == sorted(set(times))  # logged only when something changed
    created = [u for u in updates if any(e.id == "objective" for e in u.message.entities)]
    assert created and created[0].log_time_ns < time_ns(finished)
    deleted = [u for u in updates if any(d.id == "objective" for d in u.message.deletions)]
    assert deleted and deleted[0].log_time_ns >= time_ns(finished)
    assert any(e.id.startswith("plane_") for e in deleted[0].message.entities)


def test_force_arrows_scale_and_clip(run):
    updates = list(iter_messages(run["path"], ("/forces",)))
    forces = run["recorder"].forces
    ids = set()
    for update, force in zip(updates, forces, strict=True):
        arrows = {e.id: e.arrows[0] for e in update.message.entities}
        ids |= arrows.keys()
        if not np.any(force):  # the final state: no force, every arrow deleted
            assert not arrows and update.message.deletions
            continue
        total = arrows["total"]
        length = total.shaft_length + total.head_length
        assert math.isclose(length, min(ARROW_M_PER_UNIT * np.hypot(*force), ARROW_MAX_M), rel_tol=1e-6)
        q = total.pose.orientation
        assert math.isclose(2 * math.atan2(q.z, q.w), math.atan2(force[1], force[0]), abs_tol=1e-9)
    assert {"attractive", "repulsive", "virtual", "total"} <= ids


def test_an_odometry_run_logs_the_believed_pose_and_its_error(tmp_path):
    overrides = ['sensors.pose="odometry"', "sensors.odometry_noise=0.02", "run.time_limit_s=6"]
    scenario = load_scenario("single_box", overrides)
    log = make_log(tmp_path / "odometry.mcap", scenario)
    result = run_scenario(scenario, observers=(log,))
    log.close(result.summary.to_dict())
    beliefs = [m.message for m in iter_messages(tmp_path / "odometry.mcap", ("/robot/odometry",))]
    metrics = [m.message for m in iter_messages(tmp_path / "odometry.mcap", ("/metrics",))]
    assert len(beliefs) == len(result.times)
    truth, belief = result.positions[-1], beliefs[-1].pose.position
    error = metrics[-2]["odometry_error_m"]  # the last planner tick (the final tick has no belief)
    assert error == pytest.approx(math.dist(truth, (belief.x, belief.y)), abs=1e-9)
    assert 0.0 < error < 0.5
    tfs = [m.message.transforms for m in iter_messages(tmp_path / "odometry.mcap", ("/tf",))]
    drifts = [t[0] for t in tfs if t[0].child_frame_id == "odom"]
    assert len(drifts) == len(beliefs)
    # world -> odom carries the last belief onto the true pose: the transform of a pose in odom
    drift, last = drifts[-1], beliefs[-1].pose
    turn = 2 * math.atan2(drift.rotation.z, drift.rotation.w)
    mapped = (
        drift.translation.x + math.cos(turn) * last.position.x - math.sin(turn) * last.position.y,
        drift.translation.y + math.sin(turn) * last.position.x + math.cos(turn) * last.position.y,
    )
    pose = list(iter_messages(tmp_path / "odometry.mcap", ("/robot/pose",)))[len(beliefs) - 1].message.pose
    assert mapped == pytest.approx((pose.position.x, pose.position.y), abs=1e-9)
    believed_yaw = 2 * math.atan2(last.orientation.z, last.orientation.w)
    true_yaw = 2 * math.atan2(pose.orientation.z, pose.orientation.w)
    assert math.remainder(turn + believed_yaw - true_yaw, math.tau) == pytest.approx(0.0, abs=1e-9)


def test_metrics_json(run):
    records = [m.message for m in iter_messages(run["path"], ("/metrics",))]
    assert len(records) == len(run["result"].times) + 1
    keys = {
        "time_s",
        "speed_mps",
        "distance_to_goal_m",
        "force_attractive",
        "force_repulsive",
        "force_virtual",
        "force_total",
        "mode",
        "command_v_mps",
        "command_omega_radps",
        "odometry_error_m",
    }  # a value that is missing or not finite is left out
    assert all(set(record) <= keys for record in records)
    assert all("odometry_error_m" not in record for record in records)  # the planner used the true pose
    escaping = [record for record in records if record["mode"] == "escaping"]
    assert escaping and all("force_virtual" in record for record in escaping)
    assert all(set(record) == keys - {"odometry_error_m"} for record in escaping)
    assert {record["mode"] for record in records} >= {"normal", "escaping"}
    last = records[-1]
    goal = np.array(run["scenario"].robot.goal)
    final = np.array(run["result"].track().final_pose[:2])
    assert math.isclose(last["distance_to_goal_m"], np.hypot(*(goal - final)), rel_tol=1e-9)
    assert last["mode"] == "finished"


def test_path_and_flushes_about_once_per_simulated_second(run):
    paths = list(iter_messages(run["path"], ("/path",)))
    assert TIME_LIMIT_S <= len(paths) <= TIME_LIMIT_S + 2  # at the first tick, every second, at close
    (line,) = paths[-1].message.entities[0].lines
    end = line.points[-1]
    assert (end.x, end.y) == pytest.approx(run["result"].track().final_pose[:2])
    with open(run["path"], "rb") as stream:
        chunks = sum(isinstance(r, Chunk) for r in StreamReader(stream, emit_chunks=True).records)
    assert TIME_LIMIT_S - 2 <= chunks <= TIME_LIMIT_S + 3


def test_the_latest_path_message_before_any_time_holds_the_whole_path_up_to_then(run):
    """What a viewer shows after a seek: the one entity `path`, from the start to about then."""
    contents = run["contents"]
    paths = list(iter_messages(run["path"], ("/path",)))
    times = np.array([p.log_time_ns for p in paths])
    assert times[0] == 0 and np.all(np.diff(times) > 0)
    assert np.diff(times).max() <= time_ns(FLUSH_PERIOD_S)
    for update in paths:
        assert not update.message.deletions
        (entity,) = update.message.entities
        assert (entity.id, entity.frame_id, entity.lifetime.seconds, entity.lifetime.nanos) == (
            PATH_ID,
            "world",
            0,
            0,
        )
        (line,) = entity.lines
        polyline = np.array([(p.x, p.y) for p in line.points])
        travelled = contents.positions[contents.times_ns <= update.log_time_ns]
        assert polyline[0] == pytest.approx(travelled[0]) and polyline[-1] == pytest.approx(travelled[-1])
        assert len(polyline) < len(travelled) or len(travelled) <= 2  # simplified
        assert distances_to_polyline(travelled, polyline).max() <= PATH_TOLERANCE_M + 1e-9
    for seek_ns in np.linspace(0, contents.times_ns[-1], 50).astype(np.int64):
        latest = times[np.searchsorted(times, seek_ns, side="right") - 1]
        assert seek_ns - latest <= time_ns(FLUSH_PERIOD_S)
    assert len(paths[-1].message.entities[0].lines[0].points) < 100  # about 4 m travelled


def test_the_log_grows_linearly_with_the_run_and_every_path_message_stays_whole(tmp_path):
    """vfh looks for a way to the walled-in goal as long as the run lasts (830 m of turns in 30
    minutes): bytes per simulated minute as in one minute, whole paths after any seek."""
    sizes = {}
    for minutes in (1, 30):
        scenario = load_scenario("walled_goal", ["planner.name=vfh", f"run.time_limit_s={60 * minutes}"])
        path = tmp_path / f"walled_goal-{minutes}.mcap"
        with McapLog(path, scenario, scan_bearings(scenario), {}) as log:
            summary = run_scenario(scenario, (log,)).summary
            log.close(summary.to_dict())
        assert summary.outcome == "timeout" and summary.path_length_m > 13 * minutes
        sizes[minutes] = path.stat().st_size / minutes
    assert sizes[30] <= 1.1 * sizes[1]  # bytes per simulated minute
    contents = read_log(path)
    paths = list(iter_messages(path, ("/path",)))
    times = np.array([p.log_time_ns for p in paths])
    assert 1800 <= len(paths) <= 1802 and np.all(np.diff(times) > 0)  # every second, and at close
    for seek_ns in np.linspace(0, contents.times_ns[-1], 5).astype(np.int64)[1:]:
        update = paths[np.searchsorted(times, seek_ns, side="right") - 1]  # what a viewer keeps
        polyline = np.array([(p.x, p.y) for p in update.message.entities[0].lines[0].points])
        travelled = contents.positions[contents.times_ns <= update.log_time_ns]
        assert seek_ns - update.log_time_ns <= time_ns(FLUSH_PERIOD_S)
        assert polyline[0] == pytest.approx(travelled[0]) and polyline[-1] == pytest.approx(travelled[-1])
        assert distances_to_polyline(travelled, polyline).max() <= PATH_TOLERANCE_M + 1e-9


def distances_to_polyline(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Distance from each point to the nearest edge (or the single vertex) of `polyline`."""
    if len(polyline) == 1:
        return np.hypot(*(points - polyline[0]).T)
    return np.min([distances_to_segment(points, a, b) for a, b in itertools.pairwise(polyline)], axis=0)


def test_every_channel_has_a_foxglove_schema_or_a_plain_json_schema(run):
    """Viewers refuse a JSON schema whose types are not plain (e.g. ["number", "null"])."""
    with open(run["path"], "rb") as stream:
        summary = make_reader(stream).get_summary()
    json_topics = {"/metrics": METRICS_JSON_SCHEMA, "/run/events": EVENTS_JSON_SCHEMA}
    for channel in summary.channels.values():
        schema = summary.schemas[channel.schema_id]
        if channel.topic in json_topics:
            assert (channel.message_encoding, schema.encoding) == ("json", "jsonschema")
            continue
        assert channel.message_encoding == schema.encoding == "protobuf", channel.topic
        assert schema.name == EXPECTED_SCHEMAS[channel.topic]
    plain = {"number": (int, float), "string": (str,), "array": (list,)}
    for topic, expected in json_topics.items():
        (channel,) = [c for c in summary.channels.values() if c.topic == topic]
        document = json.loads(summary.schemas[channel.schema_id].data)
        assert document == expected and document["type"] == "object"
        assert {spec["type"] for spec in document["properties"].values()} <= set(plain)
        records = [m.message for m in iter_messages(run["path"], (topic,))]
        assert records, topic
        for record in records:
            assert set(document["required"]) <= set(record) <= set(document["properties"])
            for key, value in record.items():
                spec = document["properties"][key]
                assert isinstance(value, plain[spec["type"]]), (topic, key, value)
                numbers = value if spec["type"] == "array" else [value] if spec["type"] == "number" else []
                assert all(type(v) in (int, float) and math.isfinite(v) for v in numbers), (key, value)


def test_truncated_file_keeps_its_complete_chunks(run, tmp_path):
    data = run["path"].read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    full, partial = run["contents"], read_log(cut)
    n = len(partial.times_ns)
    assert 0 < n < len(full.times_ns)
    assert not partial.complete and partial.summary is None
    assert np.all(np.diff(partial.times_ns) > 0)
    np.testing.assert_array_equal(partial.times_ns, full.times_ns[:n])
    np.testing.assert_array_equal(partial.positions, full.positions[:n])
    assert partial.metadata[METADATA_NAME]["scenario"] == "paper_c_escape"


_CHILD = textwrap.dedent(
    """
    import sys, time
    from pathlib import Path
    from vplane_mj.logs.writer import McapLog
    from vplane_mj.robots.facts import robot_radius_m
    from vplane_mj.scenario import load_scenario
    from vplane_mj.sim.loop import Tick, run_scenario
    from vplane_mj.sim.sensors import scan_bearings

    class Slow:  # keep the run going until it is killed
        def on_tick(self, tick):
            time.sleep(0.004)
        def on_event(self, time_s, event):
            pass

    scenario = load_scenario("paper_c_escape", ["run.time_limit_s=300"])
    bearings = scan_bearings(scenario)
    log = McapLog(Path(sys.argv[1]), scenario, bearings, {})
    run_scenario(scenario, observers=(log, Slow()))
    log.close()
    """
)


def test_log_of_a_killed_writer_is_readable(tmp_path):
    path = tmp_path / "killed.mcap"
    child = subprocess.Popen([sys.executable, "-c", _CHILD, str(path)])
    try:
        deadline = time.monotonic() + 15
        poses = 0
        while poses < 40 and time.monotonic() < deadline and child.poll() is None:
            time.sleep(0.1)
            if path.exists():
                poses = len(read_log(path).times_ns)
        assert child.poll() is None, "the child ended before it could be killed"
        os.kill(child.pid, signal.SIGKILL)
    finally:
        if child.poll() is None:
            child.kill()
        child.wait()
    contents = read_log(path)
    assert not contents.complete and contents.summary is None
    assert len(contents.times_ns) >= 40
    assert np.all(np.diff(contents.times_ns) > 0)
    assert contents.times_ns[0] == 0
    assert contents.topics["/world"][1] == 1
    assert contents.metadata[METADATA_NAME]["planner"] == "vplane"


def test_warning_levels_close_is_idempotent_and_ticks_after_close_are_ignored(tmp_path):
    scenario = load_scenario("paper_c_escape")
    path = tmp_path / "events.mcap"
    log = make_log(path, scenario)
    log.on_event(0.5, Event(EventKind.COLLISION, "collision at (1.00, 2.00)", {"point": (1.0, 2.0)}))
    log.on_event(1.0, Event(EventKind.GAVE_UP, "gave up after 3 escapes"))
    log.on_event(1.5, Event(EventKind.ESCAPE_STARTED, "escape started", {"objective": (3.0, 4.0)}))
    log.close({"outcome": "stuck", "value": np.float64(1.5), "gap": [math.nan, np.int64(2)]})
    log.close()
    log.on_event(2.0, Event(EventKind.TIME_LIMIT, "ignored"))
    contents = read_log(path)
    assert [(e.time_s, e.kind, e.text, e.data) for e in contents.events] == [
        (0.5, EventKind.COLLISION, "collision at (1.00, 2.00)", {"point": (1.0, 2.0)}),
        (1.0, EventKind.GAVE_UP, "gave up after 3 escapes", {}),
        (1.5, EventKind.ESCAPE_STARTED, "escape started", {"objective": (3.0, 4.0)}),
    ]
    levels = [m.message.level for m in iter_messages(path, ("/events",))]
    assert levels == [3, 3, 2]  # WARNING, WARNING, INFO
    assert contents.summary == {"outcome": "stuck", "value": 1.5, "gap": [None, 2]}
    assert len(contents.times_ns) == 0 and contents.complete


def test_ticks_are_written_in_order_with_the_forces_they_had_when_they_came(tmp_path):
    """Ticks are written in batches, yet a planner that reuses its force array, and an event
    between ticks, change nothing in the file."""
    scenario = load_scenario("paper_c_escape")
    path = tmp_path / "batched.mcap"
    log = make_log(path, scenario)
    force = np.zeros(2)  # one array, changed in place at every tick
    ranges = np.full(len(scan_bearings(scenario)), np.nan)
    for k in range(5):
        force[:] = (k + 1.0, 0.0)
        decision = Decision(force=force, mode="normal")
        log.on_tick(Tick(0.1 * k, np.array([1.0, 1.0]), 0.0, 0.0, ranges, decision, (0.0, 0.0)))
        if k == 2:
            log.on_event(0.2, Event(EventKind.LOCAL_MINIMUM, "between ticks"))
    force[:] = (99.0, 0.0)
    log.close()
    metrics = [m.message for m in iter_messages(path, ("/metrics",))]
    assert [record["force_total"] for record in metrics] == [1.0, 2.0, 3.0, 4.0, 5.0]
    with open(path, "rb") as stream:
        order = [
            (channel.topic, message.log_time)
            for _, channel, message in make_reader(stream).iter_messages(log_time_order=False)
            if channel.topic in ("/metrics", "/events")
        ]
    assert order.index(("/events", time_ns(0.2))) == order.index(("/metrics", time_ns(0.2))) + 1


CYLINDER_APF = """
format = 1
name = "cylinder_apf"
[world]
size = [4.0, 3.0]
border = false
[[world.obstacles]]
kind = "cylinder"
center = [2.0, 1.5]
radius = 0.3
[robot]
start = [0.5, 1.5]
goal = [3.5, 1.5]
[planner]
name = "apf"
[run]
time_limit_s = 1.0
"""


def test_cylinders_no_border_and_a_planner_without_virtual_parts(scenario_from, tmp_path):
    scenario = scenario_from(CYLINDER_APF)
    path = tmp_path / "apf.mcap"
    log = make_log(path, scenario)
    result = run_scenario(scenario, observers=(log,))
    log.close(result.summary.to_dict())
    contents = read_log(path)
    assert set(EXPECTED_SCHEMAS) | {"/metrics", "/run/events"} == set(contents.topics)
    assert contents.topics["/virtual"][1] == 1  # the empty update at time 0 only
    (world,) = iter_messages(path, ("/world",))
    entities = {entity.id: entity for entity in world.message.entities}
    assert "border" not in entities
    (cylinder,) = entities["obstacle_0"].cylinders
    assert math.isclose(cylinder.size.x, 0.6) and cylinder.size.z == OBSTACLE_HEIGHT_M
    ids = {e.id for u in iter_messages(path, ("/forces",)) for e in u.message.entities}
    assert ids <= {"attractive", "repulsive", "total"} and "total" in ids
    metrics = [m.message for m in iter_messages(path, ("/metrics",))]
    assert all("force_virtual" not in m for m in metrics)
    assert len(contents.times_ns) == len(result.times) + 1 and contents.complete


@pytest.mark.skipif(importlib.util.find_spec("pymcap_cli") is None, reason="pymcap-cli is not installed")
def test_pymcap_cli_doctor_accepts_the_file(run, console_script):
    command = [console_script("pymcap-cli"), "doctor", str(run["path"])]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr


def test_the_shipped_layout_uses_only_what_the_log_has(run):
    """Every panel of docs/foxglove-layout.json draws a topic, field or frame of the log."""
    layout = json.loads((Path(__file__).parents[1] / "docs" / "foxglove-layout.json").read_text())
    panels = layout["configById"]
    three_d = panels.pop("3D!vplane")
    topics = run["contents"].topics
    shown = [topic for topic, config in three_d["topics"].items() if config.get("visible")]
    only_some = {"/world/moving", "/tracks"}  # in logs of worlds with moving obstacles, of runs with tracks
    assert set(shown) == {"/world", "/scan", "/forces", "/virtual", "/path", *only_some}
    assert set(shown) - only_some <= set(topics) and not only_some & set(topics)
    assert three_d["followTf"] == "base_link_xy"  # a frame of /tf that follows the robot without turning
    fields = [path["value"] for config in panels.values() for path in config.get("paths", [])]
    assert fields and all(field.startswith("/metrics.") for field in fields)
    assert {field.removeprefix("/metrics.") for field in fields} <= set(METRICS_JSON_SCHEMA["properties"])
    assert set(json.dumps(layout["layout"]).split('"')) >= {"3D!vplane", *panels}
