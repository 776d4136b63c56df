"""The paper's four figures: the C and H obstacles, passed (avoid) and escaped (escape).

Runs the built-in scenarios paper_c_avoid, paper_c_escape, paper_h_avoid and paper_h_escape
with `vplane` (and `apf` for contrast), headless, prints each run's summary line, writes each
run's `.json` summary and one figure: a row per scenario, a column per planner, the world and
the path travelled, coloured by planner mode, with the virtual objectives (sky-blue dots), the
virtual planes (dashed black lines), the local minima (black crosses) and any collision, in the
render's colours (`vplane_mj.viz.palette`).

    python examples/paper_figures.py                      # logs/paper_figures/paper_figures.png
    python examples/paper_figures.py --planners vplane,vplane_plus,apf --seed 3 --noise 0.01
"""

from __future__ import annotations

import argparse
import sys
from argparse import RawDescriptionHelpFormatter
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: files only, never a window
import matplotlib.pyplot as plt
import numpy as np

import vplane_mj
from vplane_mj import EventKind, RunRecord
from vplane_mj.viz.plots import (
    draw_collision,
    draw_local_minimum,
    draw_objective,
    draw_path,
    draw_plane,
    draw_world,
    label_modes,
)

PAPER_SCENARIOS = ("paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape")
PLANE_EVENTS = (EventKind.ESCAPE_FINISHED, EventKind.PLANE_CREATED)
"""Events whose `e1` and `e2` are the ends of a virtual plane just created."""
VIEW_MARGIN_M = 1.0
"""Space shown around the start, the goal and the paths (m)."""


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=RawDescriptionHelpFormatter)
    parser.add_argument("--planners", default="vplane,apf", help="comma-separated planners (a column each)")
    parser.add_argument("--scenarios", default=",".join(PAPER_SCENARIOS), help="comma-separated scenarios")
    parser.add_argument("--seed", type=int, default=0, help="run.seed: drives the sensor noise")
    parser.add_argument("--noise", type=float, default=0.0, help="sonar range noise, std in m")
    parser.add_argument("--time-limit", type=float, help="simulated seconds per run (default: 300)")
    parser.add_argument("--out", type=Path, default=Path("logs/paper_figures"), help="output directory")
    return parser.parse_args()


def summary_line(record: RunRecord) -> str:
    """The line `vplane-mj run` prints for a run, from the public summary."""
    s = record.summary
    clearance = "n/a" if s.min_clearance_m is None else f"{s.min_clearance_m:.3f} m"
    return (
        f"{s.scenario} [{s.planner}, seed {s.seed}]: {s.outcome} after {s.sim_time_s:.2f} s simulated, "
        f"path {s.path_length_m:.2f} m, collisions {s.collisions}, min clearance {clearance}, "
        f"local minima {s.local_minima}, escapes {s.escapes}, wall {s.wall_time_s:.2f} s"
    )


def draw_events(axes, record: RunRecord) -> None:
    """The escape's virtual objects and the local minima and collisions, from the run's events.

    vplane reports a virtual objective when an escape starts (`objective`) and the virtual
    plane (`e1`, `e2`) when the objective is reached; vplane_plus may add planes later.
    """
    labelled: set[str] = set()

    def first(mark: str) -> bool:  # one legend entry per kind of mark
        new = mark not in labelled
        labelled.add(mark)
        return new

    times, positions = record.trajectory.times, record.trajectory.positions
    for event in record.events:
        data = event.data
        if event.kind is EventKind.ESCAPE_STARTED and "objective" in data:
            draw_objective(axes, data["objective"], first("objective"), size_pt=9.0)
        if event.kind in PLANE_EVENTS and {"e1", "e2"} <= data.keys():
            draw_plane(axes, data["e1"], data["e2"], first("plane"))
        if event.kind is EventKind.LOCAL_MINIMUM:  # no point of its own: where the robot was
            where = positions[min(np.searchsorted(times, event.time_s), len(positions) - 1)]
            draw_local_minimum(axes, where, first("local minimum"))
        if event.kind is EventKind.COLLISION and "point" in data:
            draw_collision(axes, data["point"], first("collision"))


def view_of(records: list[RunRecord]) -> tuple[tuple[float, float], tuple[float, float]]:
    """x and y limits (m) around the start, the goal and every path of these runs of one scenario
    (the paper's obstacles lie between the start and the goal, so they are in view too)."""
    scenario = records[0].scenario
    points = np.vstack(
        [*(record.trajectory.positions for record in records), [scenario.robot.start, scenario.robot.goal]]
    )
    low, high = points.min(axis=0) - VIEW_MARGIN_M, points.max(axis=0) + VIEW_MARGIN_M
    return (float(low[0]), float(high[0])), (float(low[1]), float(high[1]))


def outcome_text(record: RunRecord) -> str:
    s = record.summary
    if s.reached:
        return f"reached in {s.time_to_goal_s:.1f} s, path {s.path_length_m:.2f} m, escapes {s.escapes}"
    return f"{s.outcome} after {s.sim_time_s:.1f} s, local minima {s.local_minima}"


def main() -> None:
    args = parse_args()
    planners = args.planners.split(",")
    scenarios = args.scenarios.split(",")
    overrides = [f"run.seed={args.seed}", f"sensors.noise_std={args.noise}"]
    if args.time_limit is not None:
        overrides.append(f"run.time_limit_s={args.time_limit}")

    # Every scenario and planner loaded and validated first, so bad input stops before any run.
    chosen = {
        (name, planner): vplane_mj.load_scenario(name, overrides=[*overrides, f"planner.name={planner}"])
        for name in scenarios
        for planner in planners
    }
    # One run each; each writes its .json summary into --out.
    records: dict[tuple[str, str], RunRecord] = {}
    for key, scenario in chosen.items():
        record = records[key] = vplane_mj.run(scenario, out=args.out, log=False, render=False)
        print(summary_line(record))
        for path in record.files.values():
            print(f"wrote {path}")

    # A row per scenario, a column per planner; a scenario's panels share one view.
    figure, grid = plt.subplots(
        len(scenarios), len(planners), figsize=(5.2 * len(planners), 3.0 * len(scenarios)), squeeze=False
    )
    for row, name in enumerate(scenarios):
        xlim, ylim = view_of([records[name, planner] for planner in planners])
        for column, planner in enumerate(planners):
            axes, record = grid[row, column], records[name, planner]
            draw_world(axes, record.scenario)
            draw_path(axes, record.trajectory.positions, record.trajectory.modes)
            draw_events(axes, record)
            label_modes(axes, record.trajectory.modes)
            axes.set(xlim=xlim, ylim=ylim)
            axes.set_title(f"{name}, {planner}\n{outcome_text(record)}", fontsize=10)
            if row < len(scenarios) - 1:  # the axis labels once: along the bottom and the left
                axes.set_xlabel("")
            if column > 0:
                axes.set_ylabel("")
    # One legend for the figure: every label that some panel has, once.
    legend: dict[str, object] = {}
    for axes in grid.flat:
        for handle, label in zip(*axes.get_legend_handles_labels(), strict=True):
            legend.setdefault(label, handle)
    figure.legend(legend.values(), legend.keys(), loc="lower center", ncol=min(len(legend), 6), fontsize=10)
    figure.suptitle(f"The paper's scenarios (seed {args.seed}, sonar noise {args.noise:g} m)", fontsize=13)
    figure.tight_layout(rect=(0, 0.06, 1, 1), w_pad=2.0, h_pad=2.0)
    path = args.out / "paper_figures.png"
    figure.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    try:
        main()
    except vplane_mj.VPlaneError as exc:  # bad input: the message names the key and the reason
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
