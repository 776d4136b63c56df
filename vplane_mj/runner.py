"""One run from Python (`vplane_mj.run`): simulate a scenario and write what `vplane-mj run`
writes (docs/interface.md section 3). The RunRecord it returns holds the summary, the
trajectory, the events and the paths of the files; the command line's `run` is this call
with its flags.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np

from vplane_mj.errors import VPlaneError, readable
from vplane_mj.files import (
    DEFAULT_OUT,
    exclusive,
    partial_path,
    prepare_out_dir,
    write_atomically,
    write_json,
)
from vplane_mj.planning.protocol.events import Event, EventKind
from vplane_mj.scenario import Scenario, load_scenario
from vplane_mj.sim.loop import RunResult, Tick, run_scenario
from vplane_mj.sim.summary import RunSummary
from vplane_mj.terminal import Interrupted

if TYPE_CHECKING:
    from vplane_mj.logs.writer import McapLog


@dataclass(frozen=True)
class RunEvent:
    """One event of a run: its simulated time (s), kind, text for people and points (x, y) in m.

    Attributes:
        time_s: When it happened (s of simulated time).
        kind: What happened (a local minimum detected, an escape begun, ...).
        text: The event as a sentence for people.
        data: Its named points (`point`, `e1`, `e2`, `objective`, `waypoint`): (x, y) in m.
    """

    time_s: float
    kind: EventKind
    text: str
    data: Mapping[str, tuple[float, float]]


@dataclass(frozen=True, eq=False)
class Trajectory:
    """The robot at every control tick.

    Attributes:
        times: The ticks' simulated times (n,), s.
        positions: The robot's centre at each tick (n, 2), m.
        yaws: Its heading at each tick (n,), rad.
        modes: The planner's mode at each tick ("normal", "escaping", ...).
        final_pose: Where the run ended: x, y (m) and yaw (rad).
    """

    times: np.ndarray
    positions: np.ndarray
    yaws: np.ndarray
    modes: tuple[str, ...]
    final_pose: tuple[float, float, float]


@dataclass(frozen=True, eq=False)
class RunRecord:
    """What a run gave.

    Attributes:
        scenario: The scenario it ran, as validated.
        summary: Its summary, the `.json` file's keys as attributes.
        trajectory: The robot at every control tick.
        events: What happened, in order.
        files: The files written, by role in the order written: "log" (.mcap), "summary"
            (.json), "render" (.png), "video" (.mp4), "ros2" (the .ros2 bag directory); empty
            when nothing was written.
    """

    scenario: Scenario
    summary: RunSummary
    trajectory: Trajectory
    events: tuple[RunEvent, ...]
    files: Mapping[str, Path]

    @property
    def reached(self) -> bool:
        """Whether the robot reached the goal."""
        return self.summary.reached

    def line(self) -> str:
        """The run in the one line `vplane-mj run` prints; a goal reached with collisions (not a
        `success`) in capitals: `REACHED WITH 3 COLLISIONS (not a success)`."""
        s = self.summary
        clearance = "n/a" if s.min_clearance_m is None else f"{s.min_clearance_m:.3f} m"
        outcome = str(s.outcome)
        if s.reached and not s.success:
            outcome = f"REACHED WITH {s.collisions} COLLISION{'S' * (s.collisions != 1)} (not a success)"
        return (
            f"{self.scenario.name} [{s.planner}, seed {s.seed}]: {outcome} after "
            f"{s.sim_time_s:.2f} s simulated, path {s.path_length_m:.2f} m, "
            f"collisions {s.collisions}, min clearance {clearance}, "
            f"local minima {s.local_minima}, escapes {s.escapes}, wall {s.wall_time_s:.2f} s"
        )


class EventRecorder:
    """An observer of a run that keeps its events, each with its time."""

    def __init__(self) -> None:
        self.events: list[RunEvent] = []

    def on_tick(self, tick: Tick) -> None:
        """Ticks are the trajectory's, which the run keeps itself."""

    def on_event(self, time_s: float, event: Event) -> None:
        self.events.append(RunEvent(time_s, event.kind, event.text, MappingProxyType(dict(event.data))))


def output_base(scenario: Scenario, out_dir: Path) -> Path:
    """The files of a run are this path with a suffix: `<out_dir>/<name>-<planner>-<seed>`."""
    return out_dir / f"{scenario.name}-{scenario.planner}-{scenario.run.seed}"


def run(
    scenario: Scenario | str | os.PathLike[str],
    out: str | os.PathLike[str] | None = DEFAULT_OUT,
    *,
    log: bool = True,
    render: bool = True,
    video: bool = False,
    ros2: bool = False,
) -> RunRecord:
    """Run a scenario (a Scenario, or a file or a built-in scenario's name) headless.

    Invalid input raises before anything is written. Interrupted (KeyboardInterrupt) during
    the simulation, the log is closed cleanly and kept; files are always whole or absent. A
    planner whose code raises does not make `run` raise: the run ends with outcome `error`,
    `summary.message` names the exception and where, `summary.traceback` holds the planner's
    traceback, and the files are written as for any run (the log up to the failing tick).

    Args:
        scenario: The scenario, or the path or built-in name of a scenario file.
        out: The folder of the files (created with its parents when missing; default
            ./logs); None writes nothing.
        log: Write the `.mcap` log.
        render: Write the `.png` top view of the run.
        video: Write an `.mp4` replay, made from the log (needs `log`).
        ros2: Write the `.ros2` directory, a ROS 2 bag made from the log (needs `log`).

    Returns:
        The scenario run, its summary, trajectory and events, and the files written by role.

    Raises:
        VPlaneError: Invalid input (a ScenarioError for the scenario), before anything is
            written.
        OutputBusy: Another process writes the same files (same `out`, name, planner and
            seed); nothing is written.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(os.fspath(scenario))
    for option, wanted, made in (("video", video, "the video"), ("ros2", ros2, "the bag")):
        if wanted and not log:
            raise VPlaneError(f"{option}: {made} is made from the log: keep log=True")
    recorder = EventRecorder()
    if out is None:
        return _record(scenario, run_scenario(scenario, (recorder,)), recorder, {})
    base = output_base(scenario, prepare_out_dir(Path(out)))
    files: dict[str, Path] = {}
    what = f"{readable(base)}.*: this run's files"
    with exclusive(base.with_name(f".{base.name}.lock"), what, "wait for it to end or choose another --out"):
        result = _simulate(scenario, base, log, recorder, files)
        try:
            _write_outputs(scenario, result, base, render, video, ros2, files)
        except Interrupted as exc:
            exc.written = dict(files)
            raise
    return _record(scenario, result, recorder, files)


def _write_outputs(
    scenario: Scenario,
    result: RunResult,
    base: Path,
    render: bool,
    video: bool,
    ros2: bool,
    files: dict[str, Path],
) -> None:
    """The files made after the run: its summary, with `render` the render, with `video` the
    video, with `ros2` the ROS 2 bag."""
    files["summary"] = write_json(base.with_suffix(".json"), result.summary.to_dict())
    if render:
        from vplane_mj.viz.render import render_top_view, run_caption, write_png

        image = render_top_view(scenario, result.track(), run_caption(result.summary))
        files["render"] = write_atomically(base.with_suffix(".png"), lambda tmp: write_png(image, tmp))
    if video:
        from vplane_mj.viz.video import write_video

        files["video"] = write_video(files["log"], base.with_suffix(".mp4"))
    if ros2:
        from vplane_mj.logs.ros2 import export_ros2

        files["ros2"] = export_ros2(files["log"], base.with_suffix(".ros2"))


def _simulate(
    scenario: Scenario, base: Path, log: bool, recorder: EventRecorder, files: dict[str, Path]
) -> RunResult:
    """The run, observed by the recorder and, with `log`, by the MCAP log, which is then closed
    under its name (also when the run is interrupted) or removed (when it fails)."""
    if not log:
        return run_scenario(scenario, (recorder,))
    target = base.with_suffix(".mcap")
    mcap = _open_log(scenario, target)
    try:
        result = run_scenario(scenario, (mcap, recorder))
    except (Interrupted, KeyboardInterrupt) as exc:
        files["log"] = _finish_log(mcap, target, None)
        if isinstance(exc, Interrupted):
            exc.written = dict(files)
        raise
    except BaseException:  # keep nothing half-written
        mcap.close()
        mcap.path.unlink(missing_ok=True)
        raise
    files["log"] = _finish_log(mcap, target, result.summary.to_dict())
    return result


def _open_log(scenario: Scenario, target: Path) -> McapLog:
    """An MCAP log written under a temporary name beside `target` (renamed when finished).

    A process killed outright leaves that `.NAME.mcap.PID-RANDOM.partial` file: its flushed part (all but
    about the last simulated second) is readable with `vplane_mj.logs.reader.read_log`.
    """
    from vplane_mj.logs.writer import McapLog
    from vplane_mj.sim.sensors import scan_bearings

    return McapLog(partial_path(target), scenario, scan_bearings(scenario), {})


def _finish_log(log: McapLog, target: Path, summary: dict | None) -> Path:
    """Close the log (with the summary when the run finished) and give it its final name."""
    log.close(summary)
    os.replace(log.path, target)
    return target


def _record(
    scenario: Scenario, result: RunResult, recorder: EventRecorder, files: dict[str, Path]
) -> RunRecord:
    trajectory = Trajectory(
        result.times, result.positions, result.yaws, tuple(result.modes), result.final_pose
    )
    return RunRecord(scenario, result.summary, trajectory, tuple(recorder.events), MappingProxyType(files))
