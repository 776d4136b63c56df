"""A world built in code: a corridor with a U trap and a few obstacles, run, saved and run again.

1. `build_scenario` makes the world from Python values, with the obstacle helpers (`wall`,
   `cup`, `box`, `cylinder`); it is validated exactly as a TOML file would be.
2. A deliberately bad obstacle shows the error: a ScenarioError naming the key and the reason.
3. The world is run with two planners (`vplane` and `apf` by default); each run's `.json`
   summary is written, and a figure of both paths.
4. The world is saved to TOML, loaded back (equal to the original) and run once more through
   the command line, `python -m vplane_mj run FILE`: the trajectory's digest is the same.

    python examples/custom_world.py                       # logs/custom_world/
    python examples/custom_world.py --planners vplane,bug2 --noise 0.01 --seed 2
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from argparse import RawDescriptionHelpFormatter
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: files only, never a window
import matplotlib.pyplot as plt

import vplane_mj
from vplane_mj import Scenario, ScenarioError, box, build_scenario, cup, cylinder, wall
from vplane_mj.viz.plots import draw_path, draw_world, label_modes


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=RawDescriptionHelpFormatter)
    parser.add_argument("--planners", default="vplane,apf", help="comma-separated planners to run")
    parser.add_argument("--seed", type=int, default=0, help="run.seed: drives the sensor noise")
    parser.add_argument("--noise", type=float, default=0.0, help="sonar range noise, std in m")
    parser.add_argument("--time-limit", type=float, default=120.0, help="simulated seconds per run")
    parser.add_argument("--out", type=Path, default=Path("logs/custom_world"), help="output directory")
    return parser.parse_args()


def corridor_trap(planner: str, seed: int, noise: float, time_limit_s: float) -> Scenario:
    """A 12 x 6 m arena; a corridor 7 m long and 4 m wide between two walls; in it a U trap whose
    mouth faces the start, a box on each side and a cylinder near the exit. Metres and degrees."""
    return build_scenario(
        "corridor_trap",
        description="a corridor with a U trap facing the start, two boxes and a cylinder",
        size=(12.0, 6.0),
        start=(1.0, 3.0),
        goal=(11.0, 3.0),
        obstacles=[
            wall((3.0, 1.0), (10.0, 1.0), thickness=0.1),  # the corridor's walls
            wall((3.0, 5.0), (10.0, 5.0), thickness=0.1),
            cup((6.0, 3.0), width=1.6, depth=1.2, thickness=0.1),  # the mouth faces -x, the start
            box((3.6, 1.6), (0.5, 0.4), yaw_deg=20.0),
            box((8.2, 4.4), (0.6, 0.4), yaw_deg=-15.0),
            cylinder((9.3, 2.0), radius=0.25),
        ],
        planner=planner,
        sensors={"noise_std": noise},
        run={"seed": seed, "time_limit_s": time_limit_s},
    )


def show_validation() -> None:
    """A cup whose arms would overlap (narrower than twice its thickness) is refused before
    anything runs; the message names the source (<code>), the key and the reason."""
    try:
        build_scenario(
            "bad_world",
            size=(12.0, 6.0),
            start=(1.0, 3.0),
            goal=(11.0, 3.0),
            obstacles=[box((3.0, 3.0), (0.5, 0.5)), cup((6.0, 3.0), width=0.15, depth=1.2, thickness=0.1)],
        )
    except ScenarioError as exc:
        print(f"rejected as expected: {exc}")
    else:
        raise SystemExit("a cup narrower than twice its thickness was accepted")


def main() -> None:
    args = parse_args()
    planners = args.planners.split(",")
    show_validation()

    # The world for each planner, all validated before any run.
    worlds = {planner: corridor_trap(planner, args.seed, args.noise, args.time_limit) for planner in planners}
    records = {}  # each run writes its .json summary into --out
    for planner, scenario in worlds.items():
        record = records[planner] = vplane_mj.run(scenario, out=args.out, log=False, render=False)
        s = record.summary
        print(
            f"{s.scenario} [{s.planner}, seed {s.seed}]: {s.outcome} after {s.sim_time_s:.2f} s simulated, "
            f"path {s.path_length_m:.2f} m, collisions {s.collisions}, local minima {s.local_minima}, "
            f"escapes {s.escapes}"
        )
        print(f"wrote {record.files['summary']}")

    # Both paths side by side in the world drawn from the scenario.
    figure, panels = plt.subplots(1, len(planners), figsize=(6.5 * len(planners), 3.8), squeeze=False)
    for axes, (planner, record) in zip(panels[0], records.items(), strict=True):
        draw_world(axes, record.scenario)
        draw_path(axes, record.trajectory.positions, record.trajectory.modes)
        label_modes(axes, record.trajectory.modes)
        axes.set_title(f"{planner}: {record.summary.outcome}, path {record.summary.path_length_m:.2f} m")
        axes.legend(loc="lower left", fontsize=7)
    figure.tight_layout()
    figure_path = args.out / "custom_world.png"
    figure.savefig(figure_path, dpi=110)
    print(f"wrote {figure_path}")

    # Save the first planner's world; it loads back equal, and the command line runs it alike.
    first = planners[0]
    scenario = records[first].scenario
    toml_path = scenario.save(args.out / "corridor_trap.toml")
    print(f"wrote {toml_path}")
    if vplane_mj.load_scenario(toml_path) != scenario:
        raise SystemExit(f"{toml_path} does not load back equal to the scenario built in code")
    print(f"loaded back: {toml_path} equals the scenario built in code")
    again = args.out / "again"
    command = [sys.executable, "-m", "vplane_mj", "run", str(toml_path), "--no-log", "--no-render"]
    done = subprocess.run([*command, "--out", str(again)], capture_output=True, text=True, check=False)
    if done.returncode not in (0, 1):  # 0: reached, 1: not reached; 2 would be a rejected file
        raise SystemExit(f"vplane-mj run {toml_path} failed: {done.stderr.strip()}")
    print(done.stdout.strip())
    summary_path = again / f"corridor_trap-{first}-{args.seed}.json"
    digest = json.loads(summary_path.read_text())["trajectory_sha256"]
    same = digest == records[first].summary.trajectory_sha256
    print(f"round trip: {'the same' if same else 'a different'} trajectory (sha256 {digest[:16]}...)")
    if not same:
        raise SystemExit("the saved world ran differently")


if __name__ == "__main__":
    try:
        main()
    except vplane_mj.VPlaneError as exc:  # bad input: the message names the key and the reason
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
