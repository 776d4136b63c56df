"""`vplane-mj video` and `run --video`: a run replayed from its log as MP4 and GIF."""

import dataclasses
import math

import imageio_ffmpeg
import numpy as np
import pytest
from PIL import Image

from vplane_mj.cli import main
from vplane_mj.logs.reader import read_log
from vplane_mj.logs.replay import load_log
from vplane_mj.logs.timeline import timeline_from_log
from vplane_mj.planning.protocol.events import EventKind
from vplane_mj.viz import palette
from vplane_mj.viz.video import FrameCanvas

TIME_LIMIT_S = 6.0  # vplane detects the trap at 5.45 s: the escape starts on screen


@pytest.fixture(scope="module")
def logged(tmp_path_factory):
    """A short `run --video`: its output directory."""
    out_dir = tmp_path_factory.mktemp("video")
    argv = ["run", "paper_c_escape", "--set", f"run.time_limit_s={TIME_LIMIT_S}", "--video"]
    assert main([*argv, "--no-render", "--out", str(out_dir)]) == 1  # timeout
    return out_dir


def decode(path) -> tuple[dict, list[np.ndarray]]:
    """The stream's metadata and every frame as an (H, W, 3) array."""
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    width, height = meta["size"]
    frames = [np.frombuffer(frame, np.uint8).reshape(height, width, 3) for frame in reader]
    return meta, frames


def decode_size(path) -> tuple[int, int]:
    """The (width, height) of a video's frames (px)."""
    reader = imageio_ffmpeg.read_frames(str(path))
    try:
        return next(reader)["size"]
    finally:
        reader.close()


@pytest.mark.slow
def test_run_writes_an_h264_mp4_in_real_time_beside_the_log(logged, capsys):
    video = logged / "paper_c_escape-vplane-0.mp4"
    assert video.is_file() and not list(logged.glob(".*partial"))
    meta, frames = decode(video)
    assert meta["codec"].startswith("h264") and meta["fps"] == 25
    width, height = meta["size"]
    assert width == 720 and height % 2 == 0  # even, as H.264 wants
    assert 0.6 * width < height < 1.8 * width  # title, caption and the plot at an aspect of 0.5 to 1.6
    assert len(frames) == TIME_LIMIT_S * 25 + 1 + 25  # every 40 ms of the run, then a 1 s hold
    first, last = frames[0].astype(int), frames[-1].astype(int)
    assert np.abs(first - last).mean() > 0.5  # the robot moved and the path grew
    assert np.abs(frames[-25].astype(int) - last).mean() < 0.1  # the held end (H.264 is lossy)
    grey = np.round(np.array(palette.OBSTACLE.rgba[:3]) * 255)
    assert (np.abs(last - grey).sum(axis=2) < 30).sum() > 1000  # the C's walls, in the render's grey


@pytest.mark.slow
def test_gif_at_a_speed(logged, capsys, tmp_path):
    target = tmp_path / "run.gif"
    log = logged / "paper_c_escape-vplane-0.mcap"
    assert main(["video", str(log), "-o", str(target), "--speed", "3"]) == 0
    assert f"wrote {target}" in capsys.readouterr().out
    with Image.open(target) as gif:
        assert gif.format == "GIF" and gif.size[0] == 480
        mp4_width, mp4_height = decode_size(logged / "paper_c_escape-vplane-0.mp4")
        assert gif.size[1] == pytest.approx(mp4_height * 480 / mp4_width, abs=2)  # the same picture
        frames = gif.n_frames
        assert gif.info.get("loop") == 0 and gif.info.get("duration") == 100
    assert frames == TIME_LIMIT_S / 3 * 10 + 1 + 10
    assert target.stat().st_size < 200_000


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["-o", "{tmp}/run.avi"], "-o must end in .mp4 or .gif"),
        (["-o", "{tmp}/run.mp4", "--speed", "0"], "--speed: must be greater than 0"),
        (["-o", "{tmp}/run.mp4", "--speed", "nan"], "--speed"),
        (["-o", "{tmp}/run.mp4", "--speed", "1e6"], "--speed"),
        (["-o", "{tmp}/run.mp4", "--speed", "0.001"], "raise --speed"),
        (["-o", "{tmp}/missing/run.mp4"], "no such directory"),
    ],
)
def test_bad_arguments_exit_2_and_write_nothing(logged, capsys, tmp_path, extra, fragment):
    argv = ["video", str(logged / "paper_c_escape-vplane-0.mcap"), *[a.format(tmp=tmp_path) for a in extra]]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and fragment in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_a_missing_log_and_video_without_a_log(capsys, tmp_path):
    assert main(["video", str(tmp_path / "none.mcap"), "-o", str(tmp_path / "x.mp4")]) == 2
    assert "no such log file" in capsys.readouterr().err
    assert main(["run", "open_field", "--video", "--no-log", "--out", str(tmp_path)]) == 2
    assert "--video" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_the_timeline_of_a_log(logged):
    log = logged / "paper_c_escape-vplane-0.mcap"
    contents = read_log(log)
    timeline = timeline_from_log(log, contents)
    ticks = len(contents.times_ns)
    assert len(timeline.times_s) == len(timeline.echoes) == len(timeline.forces) == ticks
    assert timeline.index_at(-1.0) == 0 and timeline.index_at(1e9) == ticks - 1
    assert timeline.times_s[timeline.index_at(2.0)] <= 2.0 < timeline.times_s[timeline.index_at(2.0) + 1]
    escape = next(e.time_s for e in timeline.events if e.kind is EventKind.ESCAPE_STARTED)
    for k, t in enumerate(timeline.times_s):
        # the objective exists from the escape on (until the final state); echoes lie within range
        assert (timeline.objectives[k] is not None) == (escape <= t < timeline.times_s[-1]), t
        reach = np.hypot(*(timeline.echoes[k] - timeline.poses[k, :2]).T)
        assert np.all(reach <= 3.0 + 0.1 + 1e-9)
        for x, y, dx, dy in timeline.forces[k].values():
            assert (x, y) == pytest.approx(tuple(timeline.poses[k, :2])) and math.hypot(dx, dy) <= 1.5 + 1e-9
    assert sum(len(echoes) for echoes in timeline.echoes) > 5 * ticks


def canvas_of(log, **changes) -> FrameCanvas:
    """The 720 px video canvas of a log, its timeline changed by `changes`."""
    contents, scenario = load_log(log)
    timeline = dataclasses.replace(timeline_from_log(log, contents), **changes)
    return FrameCanvas(scenario, timeline, 720, 1.0)


def frame_at(canvas: FrameCanvas, time_s: float) -> np.ndarray:
    """The frame at `time_s` as an (H, W, 3) array."""
    width, height = canvas.size
    return np.frombuffer(canvas.frame(time_s), np.uint8).reshape(height, width, 4)[..., :3]


def rgb(rgba) -> tuple[int, int, int]:
    """A palette colour's 8-bit RGB."""
    return tuple(round(channel * 255) for channel in rgba[:3])


def count(pixels: np.ndarray, colour, within: int = 0) -> int:
    """The pixels of `colour`, each channel off by at most `within` (lines are antialiased)."""
    return int((np.abs(pixels.reshape(-1, 3).astype(int) - rgb(colour)) <= within).all(axis=1).sum())


def test_the_video_s_legend_names_every_mark_it_shows(logged):
    canvas = canvas_of(logged / "paper_c_escape-vplane-0.mcap")
    (legend,) = canvas.figure.legends
    forces = ("attractive", "repulsive", "total")  # no plane before 6 s: no virtual force
    marks = [
        palette.OBSTACLE,
        palette.START,
        palette.GOAL,
        palette.path_mark("normal"),
        palette.path_mark("escaping"),  # from 5.45 s on
        palette.OBJECTIVE,
        dataclasses.replace(palette.ECHO, label="sonar echo"),
        palette.ROBOT,
        *(palette.force_mark(name) for name in forces),
    ]
    assert [text.get_text() for text in legend.get_texts()] == [mark.label for mark in marks]
    (x0, y0), (x1, y1) = canvas.axes.get_window_extent().get_points()
    for time_s, shown in (
        (3.0, [m for m in marks if m.label not in ("path: escaping", "virtual objective")]),
        (TIME_LIMIT_S - 0.2, [palette.OBJECTIVE]),
    ):
        frame = frame_at(canvas, time_s)
        plot = frame[round(frame.shape[0] - y1) : round(frame.shape[0] - y0), round(x0) : round(x1)]
        for mark in shown:  # each mark's colour shows in the plot, not only in the legend
            assert count(plot, mark.rgba, within=24) >= 3, (time_s, mark.label)


def test_the_video_draws_the_start_above_a_virtual_plane_that_crosses_it(logged):
    log = logged / "paper_c_escape-vplane-0.mcap"
    x, y = load_log(log)[1].robot.start
    canvas = canvas_of(log, planes=[[((x, y - 1.0), (x, y + 1.0))]] * len(read_log(log).times_ns))
    frame = frame_at(canvas, 3.0)  # the robot has left the start
    column, row = canvas.axes.transData.transform((x, y))
    row = round(frame.shape[0] - row)
    assert count(frame[row - 2 : row + 3, round(column) - 2 : round(column) + 3], palette.START.rgba) == 25
    column, row = canvas.axes.transData.transform((x, y + 0.5))
    row = round(frame.shape[0] - row)
    beside = frame[row - 4 : row + 5, round(column) - 4 : round(column) + 5]
    assert count(beside, palette.PLANE.rgba) >= 5  # the plane itself, under the start
