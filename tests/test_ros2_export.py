"""The ROS 2 bag of a run (`vplane-mj export ros2`, `run --ros2`), read back with the MCAP
library and Foxglove's ROS 2 decoder, a reader apart from the one that wrote it."""

import math
import os
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from vplane_mj import VPlaneError, run
from vplane_mj.cli import main
from vplane_mj.logs.reader import read_log
from vplane_mj.logs.ros2 import MARKER_TOPICS, RVIZ_CONFIG, TOPICS

TRANSIENT_LOCAL, VOLATILE = 1, 2
"""rmw durability policies as a bag's metadata writes them."""


def run_with_bag(out: Path, base: str, *argv: str) -> tuple[Path, Path]:
    """A run written with --ros2 into `out`: its log and its bag (`base` the files' name)."""
    assert main(["run", *argv, "--out", str(out), "--no-render", "--ros2"]) in (0, 1)
    return out / f"{base}.mcap", out / f"{base}.ros2"


@pytest.fixture(scope="module")
def sonar_run(tmp_path_factory):
    """paper_c_escape (the default robot's sonar ring, the true pose): its log and bag."""
    return run_with_bag(tmp_path_factory.mktemp("sonar"), "paper_c_escape-vplane-0", "paper_c_escape")


@pytest.fixture(scope="module")
def laser_run(tmp_path_factory):
    """The Jackal (a laser) steering on its EKF's pose, so that `odom` drifts from `map`."""
    overrides = [
        "robot.profile=jackal",
        "sensors.pose=ekf",
        "sensors.odometry_noise=0.05",
        "run.time_limit_s=6",
    ]
    argv = ["paper_c_avoid", *(part for key in overrides for part in ("--set", key))]
    return run_with_bag(tmp_path_factory.mktemp("laser"), "paper_c_avoid-vplane-0", *argv)


def read_bag(bag: Path) -> dict[str, list[tuple[int, object]]]:
    """Every message of the bag's MCAP file by topic: (log time ns, decoded message)."""
    (storage,) = bag.glob("*.mcap")
    messages: dict[str, list[tuple[int, object]]] = {}
    with open(storage, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        for schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=True):
            assert (schema.encoding, channel.message_encoding) == ("ros2msg", "cdr")
            messages.setdefault(channel.topic, []).append((message.log_time, decoded))
    return messages


def planar(pose) -> tuple[float, float, float]:
    """x, y and yaw of a geometry_msgs/Pose."""
    q = pose.orientation
    return (pose.position.x, pose.position.y, 2 * math.atan2(q.z, q.w))


def log_counts(log: Path) -> dict[str, int]:
    return {topic: count for topic, (_, count) in read_log(log).topics.items()}


@pytest.mark.parametrize("which", ["sonar_run", "laser_run"])
def test_every_topic_holds_a_message_for_each_of_the_log_s(request, which):
    log, bag = request.getfixturevalue(which)
    counts = {topic: len(messages) for topic, messages in read_bag(bag).items()}
    logged = log_counts(log)
    ticks = logged["/robot/pose"]
    expected = {
        "/clock": ticks,
        "/tf": ticks,
        "/ground_truth": ticks,
        "/odom": logged.get("/robot/odometry", ticks),
        "/scan": logged["/scan"],
        "/cmd_vel": logged["/metrics"],
        "/tf_static": 1,
        "/goal_pose": 1,
        "/rosout": logged["/events"],
        "/run/summary": 1,
        **{MARKER_TOPICS[topic]: count for topic, count in logged.items() if topic in MARKER_TOPICS},
    }
    plans = counts.pop("/plan")
    assert counts == expected
    assert plans >= 1
    assert set(counts) <= set(TOPICS)


def test_metadata_yaml_lists_the_topics_with_their_counts_and_qos(sonar_run):
    _, bag = sonar_run
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["version"] == 8 and info["storage_identifier"] == "mcap"
    (storage,) = info["relative_file_paths"]
    assert (bag / storage).is_file() and sorted(p.name for p in bag.iterdir()) == sorted(
        [storage, "metadata.yaml"]
    )
    counts = {topic: len(messages) for topic, messages in read_bag(bag).items()}
    listed = {entry["topic_metadata"]["name"]: entry for entry in info["topics_with_message_count"]}
    assert {topic: entry["message_count"] for topic, entry in listed.items()} == counts
    assert info["message_count"] == sum(counts.values())
    assert info["custom_data"]["vplane_mj.scenario"] == "paper_c_escape"
    for topic, entry in listed.items():
        (qos,) = yaml.safe_load(entry["topic_metadata"]["offered_qos_profiles"])
        latched = topic in ("/tf_static", "/markers/world", "/goal_pose")
        assert qos["durability"] == (TRANSIENT_LOCAL if latched else VOLATILE), topic
        assert entry["topic_metadata"]["type"] == TOPICS[topic][0]


def test_tf_static_is_offered_transient_local_in_the_mcap_file_too(sonar_run):
    _, bag = sonar_run
    (storage,) = bag.glob("*.mcap")
    with open(storage, "rb") as stream:
        summary = make_reader(stream).get_summary()
    channels = {channel.topic: channel for channel in summary.channels.values()}
    (qos,) = yaml.safe_load(channels["/tf_static"].metadata["offered_qos_profiles"])
    assert qos["durability"] == TRANSIENT_LOCAL and qos["reliability"] == 1
    schema = summary.schemas[channels["/odom"].schema_id]
    assert schema.name == "nav_msgs/msg/Odometry"
    assert b"MSG: std_msgs/Header" in schema.data and b"MSG: geometry_msgs/Quaternion" in schema.data


@pytest.mark.parametrize("which", ["sonar_run", "laser_run"])
def test_the_scans_are_the_log_s(request, which):
    log, bag = request.getfixturevalue(which)
    logged = read_log(log, ("/scan",)).messages
    scans = read_bag(bag)["/scan"]
    (mount,) = read_bag(bag)["/tf_static"][0][1].transforms
    for (ns, scan), first in zip(scans, logged, strict=True):
        assert ns == first.log_time_ns
        assert scan.header.frame_id == mount.child_frame_id
        assert np.array_equal(np.array(scan.ranges), np.array(first.message.ranges), equal_nan=True)
        assert scan.angle_min == pytest.approx(first.message.start_angle)
        assert scan.angle_max == pytest.approx(first.message.end_angle)
        assert scan.angle_min + (len(scan.ranges) - 1) * scan.angle_increment == pytest.approx(scan.angle_max)
    assert mount.transform.translation.z == pytest.approx(logged[0].message.pose.position.z)
    assert mount.child_frame_id == ("laser" if which == "laser_run" else "sonar")


@pytest.mark.parametrize(
    "which, planner_topic", [("sonar_run", "/robot/pose"), ("laser_run", "/robot/odometry")]
)
def test_odom_is_the_pose_the_planner_used_and_ground_truth_the_true_pose(request, which, planner_topic):
    log, bag = request.getfixturevalue(which)
    messages = read_bag(bag)
    for topic, logged, frame in (("/odom", planner_topic, "odom"), ("/ground_truth", "/robot/pose", "map")):
        poses = read_log(log, (logged,)).messages
        assert len(messages[topic]) == len(poses)
        for (ns, odometry), pose in zip(messages[topic], poses, strict=True):
            assert ns == pose.log_time_ns
            assert (odometry.header.frame_id, odometry.child_frame_id) == (frame, "base_link")
            assert planar(odometry.pose.pose) == pytest.approx(planar(pose.message.pose), abs=1e-12)


def transforms_at(messages, topic: str) -> dict[int, dict[str, object]]:
    """child frame -> transform, by time."""
    by_time: dict[int, dict[str, object]] = {}
    for ns, frames in messages[topic]:
        for frame in frames.transforms:
            by_time.setdefault(ns, {})[frame.child_frame_id] = frame
    return by_time


def compose(a, b):
    """Two planar poses (x, y, yaw) chained: b given in a's frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2])


def test_the_tf_tree_joins_map_odom_base_link_and_the_sensor(laser_run):
    log, bag = laser_run
    messages = read_bag(bag)
    (static,) = transforms_at(messages, "/tf_static").values()
    parents = {child: frame.header.frame_id for child, frame in static.items()}
    dynamic = transforms_at(messages, "/tf")
    truth = {m.log_time_ns: planar(m.message.pose) for m in read_log(log, ("/robot/pose",)).messages}
    assert set(dynamic) == set(truth)
    drifted = 0
    for ns, frames in dynamic.items():
        tree = {**parents, **{child: frame.header.frame_id for child, frame in frames.items()}}
        for frame in ("laser", "base_link", "odom"):
            chain = [frame]
            while chain[-1] in tree:
                chain.append(tree[chain[-1]])
            assert chain[-1] == "map", chain
        odom, base = (frames[child].transform for child in ("odom", "base_link"))
        here = compose(planar_transform(odom), planar_transform(base))
        assert here == pytest.approx(truth[ns], abs=1e-9)
        drifted += math.hypot(odom.translation.x, odom.translation.y) > 1e-4
    assert drifted > 0  # the EKF's pose drifted from the truth, and map -> odom says by how much


def planar_transform(transform) -> tuple[float, float, float]:
    q = transform.rotation
    return (transform.translation.x, transform.translation.y, 2 * math.atan2(q.z, q.w))


def test_markers_draw_the_world_the_forces_and_the_virtual_objects(sonar_run):
    _, bag = sonar_run
    messages = read_bag(bag)
    ((_, world),) = messages["/markers/world"]
    spaces = Counter(marker.ns for marker in world.markers)
    assert spaces["robot"] >= 2 and spaces["goal"] == 1 and any(ns.startswith("obstacle_") for ns in spaces)
    robot = [marker for marker in world.markers if marker.ns == "robot"]
    assert all(marker.header.frame_id == "base_link" and marker.frame_locked for marker in robot)
    arrows = [m for _, array in messages["/markers/forces"] for m in array.markers if m.action == 0]
    assert arrows and all(m.type == 0 and len(m.points) == 2 and m.header.frame_id == "map" for m in arrows)
    planes = [
        m for _, array in messages["/markers/virtual"] for m in array.markers if m.ns.startswith("plane_")
    ]
    assert planes and all(m.header.frame_id == "odom" for m in planes)
    (plan_frame,) = {path.header.frame_id for _, path in messages["/plan"]}
    assert plan_frame == "odom"
    ((_, summary),) = messages["/run/summary"]
    assert '"scenario": "paper_c_escape"' in summary.data


def test_the_rviz_configuration_shows_the_bag_s_topics():
    config = yaml.safe_load(RVIZ_CONFIG.read_text())["Visualization Manager"]
    shown = {display["Topic"]["Value"] for display in config["Displays"] if "Topic" in display}
    assert shown <= set(TOPICS) and set(MARKER_TOPICS.values()) <= shown
    assert config["Global Options"]["Fixed Frame"] == "map"


def test_export_replaces_a_bag_and_leaves_no_temporary_file(sonar_run, tmp_path, capsys):
    log, _ = sonar_run
    target = tmp_path / "bag"
    for _ in range(2):
        assert main(["export", "ros2", str(log), "-o", str(target)]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0] == f"wrote {target}" and str(RVIZ_CONFIG) in out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bag"]
    assert sorted(p.name for p in target.iterdir()) == ["bag.mcap", "metadata.yaml"]


def unwritable(tmp_path: Path) -> Path | None:
    """A directory that cannot be written into, even by root; None when there is none."""
    if os.geteuid() != 0:
        locked = tmp_path / "locked"
        locked.mkdir()
        locked.chmod(0o500)
        return locked
    return Path("/sys/kernel") if Path("/sys/kernel").is_dir() else None


@pytest.mark.parametrize("case", ["not a log", "truncated", "unwritable", "no parent", "not a bag"])
def test_bad_input_exits_2_naming_the_file_and_leaves_nothing(sonar_run, tmp_path, capsys, case):
    log, _ = sonar_run
    source, target = log, tmp_path / "bag"
    if case == "not a log":
        source = tmp_path / "notes.mcap"
        source.write_text("not an MCAP file\n")
    elif case == "truncated":
        source = tmp_path / "cut.mcap"
        source.write_bytes(log.read_bytes()[: log.stat().st_size // 2])
    elif case == "unwritable":
        locked = unwritable(tmp_path)
        if locked is None:
            pytest.skip("no unwritable directory on this system")
        target = locked / "bag"
    elif case == "no parent":
        target = tmp_path / "missing" / "bag"
    else:
        target = tmp_path / "taken"
        target.mkdir()
        (target / "keep.txt").write_text("mine")
    before = sorted(tmp_path.rglob("*"))
    try:
        code = main(["export", "ros2", str(source), "-o", str(target)])
    finally:
        if case == "unwritable" and target.parent.is_relative_to(tmp_path):
            target.parent.chmod(0o700)
    captured = capsys.readouterr()
    named = source if case in ("not a log", "truncated") else target
    assert code == 2 and captured.out == ""
    assert captured.err.startswith(f"error: {named}: ") and captured.err.count("\n") == 1, captured.err
    assert "Traceback" not in captured.err
    assert sorted(tmp_path.rglob("*")) == before


def test_run_refuses_a_bag_without_a_log(tmp_path, capsys):
    assert main(["run", "paper_c_escape", "--out", str(tmp_path), "--no-log", "--ros2"]) == 2
    assert "--ros2: the bag is made from the log" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_the_api_writes_the_bag_last_and_names_it(tmp_path):
    record = run("single_box", tmp_path, render=False, ros2=True)
    assert list(record.files) == ["log", "summary", "ros2"]
    assert record.files["ros2"] == tmp_path / "single_box-vplane-0.ros2"
    assert (record.files["ros2"] / "metadata.yaml").is_file()
    with pytest.raises(VPlaneError, match="ros2: the bag is made from the log"):
        run("single_box", tmp_path / "none", log=False, ros2=True)
    assert not (tmp_path / "none").exists()


def test_bench_writes_each_run_s_log_and_bag_beside_it(tmp_path, capsys):
    argv = ["bench", "single_box", "--planners", "apf", "--seeds", "0-1", "--jobs", "1"]
    argv += ["--out", str(tmp_path)]
    assert main([*argv, "--ros2"]) == 0
    for seed in (0, 1):
        log, bag = tmp_path / f"single_box-apf-{seed}.mcap", tmp_path / f"single_box-apf-{seed}.ros2"
        clocks = read_bag(bag)["/clock"]
        assert len(clocks) == log_counts(log)["/robot/pose"]
    assert not list(tmp_path.glob(".*.partial"))
    capsys.readouterr()
    assert main([*argv, "--ros2", "--scheduler", "tcp://127.0.0.1:9"]) == 2
    refused = "error: --ros2: the bags are written by local workers: drop --scheduler\n"
    assert capsys.readouterr().err == refused


def test_moving_obstacles_are_drawn_where_the_log_has_them(tmp_path):
    assert main(["generate", "dynabarn", "--count", "1", "--seed", "0", "--out", str(tmp_path)]) == 0
    (world,) = tmp_path.glob("*.toml")
    log, bag = run_with_bag(tmp_path, f"{world.stem}-vplane-0", str(world), "--set", "run.time_limit_s=2")
    logged = read_log(log)
    moving = read_bag(bag)["/markers/moving"]
    assert [ns for ns, _ in moving] == list(logged.obstacle_times_ns)
    for (_, array), places in zip(moving, logged.obstacle_places, strict=True):
        centres = [(m.pose.position.x, m.pose.position.y) for m in array.markers if m.action == 0]
        assert np.allclose(centres, places, rtol=0.0, atol=1e-12)
        assert {m.header.frame_id for m in array.markers} == {"map"}
