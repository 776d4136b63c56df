"""The `vplane-mj` command line (docs/command-line.md). `main(argv) -> exit status`."""

from __future__ import annotations

import argparse
import json
import os
import sys
import warnings
from collections.abc import Mapping
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import vplane_mj
from vplane_mj.errors import VPlaneError, readable, without_surrogates
from vplane_mj.files import DEFAULT_OUT, prepare_out_dir, write_atomically
from vplane_mj.planning.protocol.plugins import PlannerError
from vplane_mj.planning.protocol.registry import DEFAULT_PLANNER, PLANNERS
from vplane_mj.terminal import Interrupted, signals_raise_interrupted
from vplane_mj.worlds.dynabarn_layout import DIFFICULTIES
from vplane_mj.worlds.families import FAMILIES

if TYPE_CHECKING:
    from vplane_mj.scenario.overrides import Override
    from vplane_mj.sim.summary import RunSummary

EXIT_REACHED, EXIT_NOT_REACHED, EXIT_INVALID = 0, 1, 2
EXIT_PLANNER_RAISED = 3
"""`run`: the planner's code raised; the run ended as `error` and its outputs were written."""


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: usage errors exit 2, --help exits 0
        return int(exc.code or 0)
    _choose_gl_backend(args)
    stdout, sys.stdout = sys.stdout, _PipeSafeOutput(sys.stdout)
    try:
        return args.handler(args)
    except VPlaneError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_INVALID
    except KeyboardInterrupt:
        print("interrupted: no partial output was written", file=sys.stderr)
        return 130
    finally:
        sys.stdout.flush()
        sys.stdout = stdout


def _choose_gl_backend(args: argparse.Namespace) -> None:
    """A command that draws nothing does not load an OpenGL backend (it takes a while), unless
    the user chose one: MuJoCo picks its backend when first imported, which is after this."""
    draws = getattr(args, "draws", True) and not getattr(args, "no_render", False)
    if not draws and not vplane_mj.GL_CHOSEN_BY_USER and "mujoco" not in sys.modules:
        os.environ["MUJOCO_GL"] = "disable"


class _PipeSafeOutput:
    """stdout that outlives its reader (`vplane-mj run ... | head -1`): the command still
    finishes its work and returns its own exit status; what it prints after the reader has
    gone is discarded instead of ending it with a BrokenPipeError. File names that are not
    UTF-8 are printed with backslash escapes."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except UnicodeEncodeError:  # a file name that is not UTF-8
            return self._stream.write(without_surrogates(text))
        except BrokenPipeError:
            self._discard_from_now_on()
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._discard_from_now_on()

    def _discard_from_now_on(self) -> None:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, self._stream.fileno())  # the stream's pending bytes go there too
        os.close(devnull)

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="vplane-mj",
        description="Artificial potential fields and the virtual-plane escape, in MuJoCo.",
    )
    parser.add_argument(
        "--version",
        action="version",
        version=f"vplane-mj {vplane_mj.__version__} (contract v{vplane_mj.CONTRACT_VERSION})",
    )
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _add_run(commands)
    _add_bench(commands)
    _add_world_commands(commands)
    _add_log_commands(commands)
    listing = commands.add_parser("list", help="built-in scenarios, robot profiles and planners")
    listing.add_argument(
        "--planner",
        action="append",
        metavar="NAME|module:Class",
        help="show only this planner and its parameters (repeatable); module:Class or "
        "path/to/file.py:Class imports it",
    )
    listing.set_defaults(handler=_list, draws=False)
    return parser


def _add_run(commands) -> None:
    """`vplane-mj run`."""
    run = commands.add_parser("run", help="one headless run of a scenario")
    run.add_argument("scenario", metavar="SCENARIO", help="a TOML file or a built-in scenario name")
    run.add_argument(
        "--planner",
        metavar="NAME|module:Class",
        help="planner name (same as --set planner.name=NAME), or a planner class to import: "
        "module:Class or path/to/file.py:Class",
    )
    run.add_argument("--seed", type=int, help="random seed (same as --set run.seed=N)")
    run.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a scenario key by dotted path, e.g. planner.influence=0.6",
    )
    run.add_argument("--out", type=Path, help=f"output directory (default {DEFAULT_OUT}/)")
    run.add_argument("--no-log", action="store_true", help="do not write the .mcap log")
    run.add_argument("--no-render", action="store_true", help="do not write the .png render")
    run.add_argument("--video", action="store_true", help="also write an .mp4 replay of the run")
    run.add_argument(
        "--ros2",
        action="store_true",
        help="also write a ROS 2 bag of the run (a .ros2 directory, from the log)",
    )
    run.set_defaults(handler=_run)


def _add_bench(commands) -> None:
    """`vplane-mj bench`."""
    sweep = commands.add_parser("bench", help="many runs: scenarios x planners x seeds")
    sweep.add_argument("scenarios", nargs="+", metavar="SCENARIO")
    sweep.add_argument(
        "--planners",
        help="comma-separated planner names or classes to import, module:Class or "
        "path/to/file.py:Class (default: every planner)",
    )
    sweep.add_argument("--seeds", default="0", help="seeds, e.g. 0-19 or 0,3,5-7 (default 0)")
    sweep.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="worker processes")
    sweep.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a key of every scenario, e.g. sensors.noise_std=0.01",
    )
    sweep.add_argument("--scheduler", metavar="ADDRESS", help="run on this Dask scheduler ([dask] extra)")
    sweep.add_argument("--out", type=Path, help=f"output directory (default {DEFAULT_OUT}/)")
    sweep.add_argument(
        "--wait",
        action="store_true",
        help="if another sweep writes into the output directory, wait for it to end (default: refuse)",
    )
    sweep.add_argument(
        "--by-scenario", action="store_true", help="also print the table per scenario and planner"
    )
    sweep.add_argument(
        "--fail-on-collision",
        action="store_true",
        help="exit 1 when any run collided (default: 0 once every run finished)",
    )
    sweep.add_argument(
        "--ros2",
        action="store_true",
        help="each run also writes its log and a ROS 2 bag of it into the output directory",
    )
    sweep.set_defaults(handler=_bench, draws=False)


def _add_world_commands(commands) -> None:
    """`vplane-mj generate`, `import`, `check` and `mjcf`: scenario files and worlds."""
    gen = commands.add_parser("generate", help="write seeded scenario files of a family")
    gen.add_argument("family", metavar="FAMILY", help=f"one of: {', '.join(sorted([*FAMILIES, 'dynabarn']))}")
    gen.add_argument("--count", type=int, default=10)
    gen.add_argument("--seed", type=int, default=0)
    gen.add_argument("--out", type=Path, required=True, metavar="DIR")
    gen.add_argument(
        "--protocol",
        action="store_true",
        help="barn only: the BARN challenge's layout (4.2 x 14 m, the Jackal), passable for the Jackal",
    )
    gen.add_argument(
        "--difficulty",
        choices=DIFFICULTIES,
        help="dynabarn only: one of DynaBARN's thirds (default: the count split into easy, medium, hard)",
    )
    gen.set_defaults(handler=_generate, draws=False)

    imports = commands.add_parser("import", help="convert worlds of another simulator into scenario files")
    imports.add_argument(
        "source",
        choices=["barn", "dynabarn"],
        metavar="SOURCE",
        help="barn: BARN's Gazebo worlds; dynabarn: DynaBARN's, with the plugins that move their obstacles",
    )
    imports.add_argument(
        "paths", nargs="+", type=Path, metavar="PATH", help="a world file, or a directory of world_N.world"
    )
    imports.add_argument(
        "--plugins",
        type=Path,
        metavar="DIR",
        help="dynabarn only: where the worlds' plugins are (default: plugins/ beside each world, or it)",
    )
    imports.add_argument("--out", type=Path, required=True, metavar="DIR")
    imports.set_defaults(handler=_import, draws=False)

    check = commands.add_parser("check", help="validate scenarios only")
    check.add_argument("scenarios", nargs="+", metavar="SCENARIO")
    check.set_defaults(handler=_check, draws=False)

    export = commands.add_parser("mjcf", help="write the compiled world as one MJCF file")
    export.add_argument("scenario", metavar="SCENARIO")
    export.add_argument("-o", "--output", type=Path, required=True, metavar="FILE.xml")
    export.set_defaults(handler=_mjcf, draws=False)


def _add_log_commands(commands) -> None:
    """`vplane-mj summary`, `render`, `plot`, `video` and `export`: what a run's log gives again."""
    summary = commands.add_parser("summary", help="recompute a run's summary from its MCAP log")
    summary.add_argument("log", type=Path, metavar="LOG.mcap")
    summary.set_defaults(handler=_summary, draws=False)

    render = commands.add_parser("render", help="render a run's top-down PNG from its MCAP log")
    render.add_argument("log", type=Path, metavar="LOG.mcap")
    render.add_argument("-o", "--output", type=Path, required=True, metavar="FILE.png")
    render.set_defaults(handler=_render)

    plot = commands.add_parser("plot", help="plot a run (map, potential field, time series) from its log")
    plot.add_argument("log", type=Path, metavar="LOG.mcap")
    plot.add_argument("-o", "--output", type=Path, required=True, metavar="FILE.png")
    plot.set_defaults(handler=_plot, draws=False)

    video = commands.add_parser("video", help="replay a run from its MCAP log as a top-down video")
    video.add_argument("log", type=Path, metavar="LOG.mcap")
    video.add_argument("-o", "--output", type=Path, required=True, metavar="FILE.mp4|FILE.gif")
    video.add_argument(
        "--speed", type=float, default=1.0, help="simulated seconds per video second (default 1: real time)"
    )
    video.set_defaults(handler=_video)

    export = commands.add_parser("export", help="convert a run's MCAP log for other tools")
    formats = export.add_subparsers(dest="format", required=True, metavar="FORMAT")
    ros2 = formats.add_parser(
        "ros2", help="a ROS 2 bag (rosbag2 directory) for ros2 bag play, RViz 2, PlotJuggler, Foxglove"
    )
    ros2.add_argument("log", type=Path, metavar="LOG.mcap")
    ros2.add_argument("-o", "--output", type=Path, required=True, metavar="DIR")
    ros2.set_defaults(handler=_export_ros2, draws=False)


def _planner_name(reference: str, option: str) -> str:
    """The name of a planner given on the command line: a name as it is, or the name of the
    class an import spec names (imported and registered here: only the user's own command line
    imports anything, never a scenario file)."""
    from vplane_mj.sweeps import planner_name

    return planner_name(reference, option)


def _overrides(args: argparse.Namespace) -> list[str | Override]:
    """The `--set` overrides, then `--planner` and `--seed` as overrides named by their options."""
    from vplane_mj.scenario.overrides import Override

    extra = []
    if args.planner is not None:
        extra.append(Override(f"planner.name={_planner_name(args.planner, '--planner')}", "--planner"))
    if args.seed is not None:
        extra.append(Override(f"run.seed={args.seed}", "--seed"))
    return [*map(Override, args.set), *extra]


def _run(args: argparse.Namespace) -> int:
    from vplane_mj.runner import run
    from vplane_mj.scenario import load_scenario

    scenario = load_scenario(args.scenario, _overrides(args))
    for option, made in (("--video", "the video"), ("--ros2", "the bag")):
        if getattr(args, option[2:]) and args.no_log:
            raise VPlaneError(f"{option}: {made} is made from the log: drop --no-log")
    out_dir = prepare_out_dir(args.out or DEFAULT_OUT)
    try:
        with signals_raise_interrupted():
            record = run(
                scenario,
                out_dir,
                log=not args.no_log,
                render=not args.no_render,
                video=args.video,
                ros2=args.ros2,
            )
    except Interrupted as exc:
        _report_interrupted_run(exc)
        return exc.exit_status
    print(record.line())
    for path in record.files.values():
        print(f"wrote {path}")
    if record.summary.traceback:
        print(_planner_raised_line(record.summary, record.files), file=sys.stderr)
        return EXIT_PLANNER_RAISED
    return EXIT_REACHED if record.reached else EXIT_NOT_REACHED


def _planner_raised_line(summary: RunSummary, files: Mapping[str, Path]) -> str:
    """The one line that says the planner raised, and which files hold what."""
    where = f"the exception and the planner's traceback are in {files['summary']}"
    if "log" in files:
        where += f", the log up to it in {files['log']}"
    return f"error: {summary.message}; {where}"


def _report_interrupted_run(exc: Interrupted) -> None:
    """Say what an interruption left: the log closed cleanly up to it, or the whole outputs of a
    run that had finished and was being written."""
    if "summary" in exc.written:
        print(f"interrupted by {exc}: the run's outputs were being written", file=sys.stderr)
        closed = ""
    else:
        print(f"interrupted by {exc}: the run was stopped, no summary was written", file=sys.stderr)
        closed = " (closed cleanly, up to the interruption)"
    for path in exc.written.values():
        print(f"wrote {path}{closed}", file=sys.stderr)


def _bench(args: argparse.Namespace) -> int:
    from vplane_mj.bench.sweep import collision_line, error_lines, parse_seeds
    from vplane_mj.scenario.overrides import Override
    from vplane_mj.sweeps import SweepErrorWarning, sweep

    if args.jobs < 1:
        raise VPlaneError(f"--jobs: must be at least 1, got {args.jobs}")
    if args.ros2 and args.scheduler:
        raise VPlaneError("--ros2: the bags are written by local workers: drop --scheduler")
    references = sorted(PLANNERS) if args.planners is None else [p.strip() for p in args.planners.split(",")]
    planners = [_planner_name(reference, "--planners") for reference in references]
    seeds = parse_seeds(args.seeds)
    out_dir = args.out or DEFAULT_OUT
    try:
        with signals_raise_interrupted(), warnings.catch_warnings():
            warnings.simplefilter("ignore", SweepErrorWarning)  # the runs in error are listed below
            result = sweep(
                args.scenarios,
                planners,
                seeds,
                tuple(map(Override, args.set)),
                args.jobs,
                args.scheduler,
                out_dir,
                wait=args.wait,
                ros2=args.ros2,
            )
    except Interrupted as exc:
        end_of_progress_bar = "\n" if sys.stderr.isatty() else ""
        print(
            f"{end_of_progress_bar}interrupted by {exc}: finished runs are kept in "
            f"{out_dir / 'bench.jsonl'}; run the same command again to complete the sweep",
            file=sys.stderr,
        )
        return exc.exit_status
    print(result.table_text())
    if args.by_scenario:
        print(result.table_text(by_scenario=True))
    for line in error_lines(result.rows, Path(out_dir)):
        print(line)
    for path in result.files:
        print(f"wrote {path}")
    collided = [row for row in result.rows if row["collisions"] > 0]
    if args.fail_on_collision and collided:
        print(collision_line(collided, len(result.rows)), file=sys.stderr)
        return EXIT_NOT_REACHED
    return 0


def _generate(args: argparse.Namespace) -> int:
    """Write `count` valid scenario files of a family, each with a reference path."""
    from vplane_mj.worlds.families import generate

    if args.count < 1:
        raise VPlaneError(f"--count: must be at least 1, got {args.count}")
    if args.seed < 0:
        raise VPlaneError(f"--seed: must be at least 0, got {args.seed}")
    if args.protocol and args.family != "barn":
        raise VPlaneError(f"--protocol: only the barn family has the challenge's layout, not {args.family}")
    if args.difficulty and args.family != "dynabarn":
        raise VPlaneError(f"--difficulty: only the dynabarn family has difficulty thirds, not {args.family}")
    if args.family == "dynabarn":
        from vplane_mj.worlds.dynabarn_generate import generate_dynabarn

        cases = generate_dynabarn(args.count, args.seed, args.difficulty)
    elif args.protocol:
        from vplane_mj.worlds.barn_protocol import generate_protocol

        cases = generate_protocol(args.count, args.seed)
    else:
        cases = generate(args.family, args.count, args.seed)
    out_dir = prepare_out_dir(args.out)
    for case in cases:
        path = write_atomically(out_dir / f"{case.name}.toml", partial(Path.write_text, data=case.toml()))
        print(f"wrote {path}")
    return 0


def _import(args: argparse.Namespace) -> int:
    """Convert BARN's or DynaBARN's world files into scenario files of their layout: every file
    (and every plugin) is read and converted, and every scenario file rendered as UTF-8, before
    anything is written."""
    lines: list[str]
    if args.source == "dynabarn":
        from vplane_mj.worlds import dynabarn_import

        moving = dynabarn_import.import_worlds(args.paths, args.plugins)
        cases, lines = [world.case for world in moving], [dynabarn_import.report_line(w) for w in moving]
    else:
        if args.plugins is not None:
            raise VPlaneError("--plugins: only DynaBARN's worlds load plugins (import dynabarn)")
        from vplane_mj.worlds import barn_import

        static = barn_import.import_worlds(args.paths)
        cases, lines = [world.case for world in static], [barn_import.report_line(w) for w in static]
    texts = [case.toml().encode("utf-8") for case in cases]
    out_dir = prepare_out_dir(args.out)
    for case, text, line in zip(cases, texts, lines, strict=True):
        print(line)
        path = write_atomically(out_dir / f"{case.name}.toml", partial(Path.write_bytes, data=text))
        print(f"wrote {readable(str(path))}")
    return 0


def _check(args: argparse.Namespace) -> int:
    from vplane_mj.scenario import load_scenario

    status = 0
    for ref in args.scenarios:
        try:
            scenario = load_scenario(ref)
        except VPlaneError as exc:
            print(f"error: {exc}", file=sys.stderr)
            status = EXIT_INVALID
        else:
            print(f"ok: {ref} ({scenario.name}, planner {scenario.planner})")
    return status


def _mjcf(args: argparse.Namespace) -> int:
    import mujoco

    from vplane_mj.scenario import load_scenario
    from vplane_mj.sim.world import standalone_xml

    scenario = load_scenario(args.scenario)
    xml = standalone_xml(scenario)
    mujoco.MjModel.from_xml_string(xml)  # what we write must load on its own
    target = args.output
    _check_parent(target)
    write_atomically(target, lambda tmp: tmp.write_text(xml, encoding="utf-8"))
    print(f"wrote {target}")
    return 0


def _summary(args: argparse.Namespace) -> int:
    """Print the summary recomputed from the log; exit 1 if it disagrees with the stored one."""
    from vplane_mj.logs.replay import disagreements, load_log, summarize

    contents, scenario = load_log(args.log)
    recomputed = summarize(contents, scenario)
    events = recomputed.pop("events")
    print(json.dumps(recomputed, indent=2))
    print("events:")
    for line in events:
        print(f"  {line}")
    stored = contents.summary
    if stored is None:
        print("the log holds no stored summary (the run was interrupted or killed)")
        return 0
    differing = disagreements(recomputed, stored)
    if differing:
        print("DISAGREES with the run's stored summary: " + "; ".join(differing))
        return 1
    print("agrees with the run's stored summary")
    return 0


def _render(args: argparse.Namespace) -> int:
    from vplane_mj.logs.replay import load_log, track_from_log
    from vplane_mj.sim.summary import RunSummary
    from vplane_mj.viz.render import render_top_view, run_caption, write_png

    contents, scenario = load_log(args.log)
    _check_parent(args.output)
    caption = run_caption(RunSummary.from_dict(contents.summary)) if contents.summary else scenario.name
    image = render_top_view(scenario, track_from_log(args.log, contents), caption)
    write_atomically(args.output, lambda tmp: write_png(image, tmp))
    print(f"wrote {args.output}")
    return 0


def _plot(args: argparse.Namespace) -> int:
    from vplane_mj.logs.replay import load_log, track_from_log
    from vplane_mj.viz.plots import plot_log

    contents, scenario = load_log(args.log)
    _check_parent(args.output)
    figure = plot_log(args.log, contents, scenario, track_from_log(args.log, contents))
    write_atomically(args.output, lambda tmp: figure.savefig(tmp, format="png", dpi=100))
    print(f"wrote {args.output}")
    return 0


def _video(args: argparse.Namespace) -> int:
    from vplane_mj.viz.video import check_speed, video_format, write_video

    video_format(args.output)
    check_speed(args.speed)
    _check_parent(args.output)
    write_video(args.log, args.output, args.speed)
    print(f"wrote {args.output}")
    return 0


def _export_ros2(args: argparse.Namespace) -> int:
    from vplane_mj.logs.ros2 import RVIZ_CONFIG, export_ros2

    target = export_ros2(args.log, args.output)
    print(f"wrote {target}")
    print(f"RViz 2 configuration: {RVIZ_CONFIG}")
    return 0


def _check_parent(target: Path) -> None:
    if not target.parent.is_dir():
        raise VPlaneError(f"{target}: no such directory: {target.parent}")


def _list(args: argparse.Namespace) -> int:
    if args.planner:
        names = [_planner_name(reference, "--planner") for reference in args.planner]
    else:
        from vplane_mj.scenario import builtin_scenarios

        print("Built-in scenarios:")
        for name, description in builtin_scenarios():
            print(f"  {name:<20} {description}")
        _print_profiles()
        names = sorted(PLANNERS)
    print("\nPlanners (parameters: default, unit, meaning):")
    for name in names:
        _print_planner(name)
    return 0


def _print_profiles() -> None:
    """The robot profiles of `vplane-mj list`: size, top speed and sensor of each."""
    from vplane_mj.robots.facts import robot_body
    from vplane_mj.robots.profiles import PROFILES

    print("\nRobot profiles ([robot] profile = NAME):")
    for name, profile in PROFILES.items():
        body = robot_body(name)
        if body.disc:
            size = f"disc of {2 * body.radius_m:.3f} m"
        else:
            size = f"{body.front_m + body.rear_m:.3f} x {2 * body.half_width_m:.3f} m"
        sensor = dict(profile.sensors)
        if sensor["kind"] == "laser":
            what = f"laser {sensor['fov_deg']:g} deg, {sensor['beams']} beams, {sensor['range_min']:g}-"
            what += f"{sensor['range_max']:g} m, {sensor['rate_hz']:g} Hz"
        else:
            where = "at their places" if profile.sonar_mounts else "in a ring"
            what = f"{sensor['count']} sonars {where}, {sensor['beam_deg']:g} deg, {sensor['range_max']:g} m"
        speed = f"{profile.limits.max_speed_mps:g} m/s"
        print(f"  {name:<18} {profile.title}: {size}, {speed}, {what}")


def _print_planner(name: str) -> None:
    """One planner of `vplane-mj list`: its summary, citation and parameters (or why an
    installed one cannot be loaded)."""
    try:
        info = PLANNERS[name].info()
    except PlannerError as exc:
        print(f"  {name}: cannot be loaded: {exc}")
        return
    default = " (default)" if name == DEFAULT_PLANNER else ""
    print(f"  {name}{default}: {info.summary}")
    if info.citation:
        print(f"    after: {info.citation}")
    for key, param in info.params.items():
        print(f"    {key:<22} {param.default:<8g} {param.unit:<7} {param.doc}")
