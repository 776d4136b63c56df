"""Make the pictures of docs/method.md from the project's own code.

    python docs/figures.py [--out docs/images]

1. the local map and polar histogram in front of a C obstacle (Algorithm 1);
2. the escape geometry inside the trap: e1, e2, the bisector, the virtual new objective
   and the virtual plane (Algorithm 2);
3. the total force around the trap with the virtual plane in place (eqs. 8-10);
4. top-down renders of the four paper scenarios with `vplane`, and of `paper_c_escape` with
   `apf`, as `vplane-mj run` writes them.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from vplane_mj.geometry import shapes
from vplane_mj.geometry.synthetic import BEAM, BEARINGS, scan
from vplane_mj.planning.perception import histogram
from vplane_mj.planning.planners.vplane_geometry import plane_force
from vplane_mj.planning.protocol.registry import make_planner
from vplane_mj.planning.protocol.types import Observation
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.viz.render import render_top_view, run_caption, write_png

RADIUS = 0.11
CUP = shapes.Cup((5.0, 5.0), width=1.6, depth=1.2, thickness=0.1)
GOAL = np.array([9.0, 5.0])


def draw_obstacle(ax) -> None:
    for piece in CUP.footprint():
        (cx, cy), (hx, hy) = piece.center, piece.half
        ax.add_patch(plt.Rectangle((cx - hx, cy - hy), 2 * hx, 2 * hy, color="#2a3f7f"))


def observe(planner, position, time_s):
    obs = Observation(
        time_s,
        np.asarray(position, float),
        0.0,
        GOAL,
        0.15,
        BEARINGS,
        scan(shapes.Footprints(CUP.footprint()), position, 0.0),
        BEAM,
    )
    return planner.step(obs), obs


def histogram_figure(path: Path) -> None:
    planner = make_planner("vplane", {}, RADIUS)
    for k in range(72):  # approach the mouth from 2.3 m
        decision, obs = observe(planner, (2.1 + 0.025 * k, 5.0), k * 0.05)
        if decision.mode == "avoiding":
            break
    cells, certainty = planner.map.cells(planner.params.map_threshold)
    h = histogram.polar_histogram(
        obs.position,
        cells,
        certainty,
        planner.n_sectors,
        planner.params.window_m,
        RADIUS + planner.params.clearance_m,
    )
    fig = plt.figure(figsize=(11, 4.5))
    ax = fig.add_subplot(1, 2, 1)
    draw_obstacle(ax)
    ax.scatter(
        cells[:, 0], cells[:, 1], c=certainty, cmap="Oranges", s=18, marker="s", label="map cells (certainty)"
    )
    ax.plot(*obs.position, "go", label="robot")
    if planner.avoid_waypoint is not None:
        ax.plot(*planner.avoid_waypoint, "r*", ms=14, label="edge waypoint")
        ax.plot(*zip(obs.position, planner.avoid_waypoint, strict=True), "r--", lw=1)
    ax.set(aspect="equal", xlim=(2.5, 6.5), ylim=(3.0, 7.0), title="local sonar map")
    ax.legend(loc="lower left", fontsize=8)
    polar = fig.add_subplot(1, 2, 2, projection="polar")
    sector = 2 * math.pi / planner.n_sectors
    angles = (np.arange(planner.n_sectors) + 0.5) * sector
    blocked = h > planner.params.histogram_threshold
    polar.bar(angles, np.log1p(h), width=sector, color=np.where(blocked, "#b03a2e", "#7dcea0"))
    polar.set_title("polar histogram (log density; red: blocked)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def trapped_planner():
    planner = make_planner("vplane", {}, RADIUS)
    for k in range(140):
        observe(planner, (5.2, 5.0), k * 0.05)
    return planner


def escape_figure(path: Path) -> None:
    planner = trapped_planner()
    plane, objective = planner.pending_plane, planner.temp_goal
    trap = np.vstack(planner.echoes)
    fig, ax = plt.subplots(figsize=(6, 6))
    draw_obstacle(ax)
    ax.scatter(trap[:, 0], trap[:, 1], s=6, color="#e67e22", label="sonar echoes")
    robot = np.array([5.2, 5.0])
    ax.plot(*robot, "go", ms=10, label="robot (local minimum)")
    for end, name in ((plane.e1, "e1"), (plane.e2, "e2")):
        ax.plot(*zip(robot, end, strict=True), "k:", lw=1)
        ax.annotate(name, end, textcoords="offset points", xytext=(-18, 0))
    ax.plot(
        [plane.e1[0], plane.e2[0]],
        [plane.e1[1], plane.e2[1]],
        color="#8e44ad",
        lw=3,
        label="virtual plane (extended)",
    )
    ax.plot(*objective, "r*", ms=15, label="virtual new objective")
    ax.plot(*zip(robot, objective, strict=True), "r--", lw=1, label="bisector, away from goal")
    ax.arrow(*plane.e1, *(0.3 * plane.normal), width=0.01, color="#8e44ad")
    ax.set(aspect="equal", xlim=(3.4, 6.2), ylim=(3.6, 6.4), title="Algorithm 2: escaping the trap")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plane_field_figure(path: Path) -> None:
    planner = trapped_planner()
    plane, p = planner.pending_plane, planner.params
    xs, ys = np.meshgrid(np.linspace(3.2, 5.0, 19), np.linspace(3.6, 6.4, 23))
    u, v = np.zeros_like(xs), np.zeros_like(ys)
    for idx in np.ndindex(xs.shape):
        point = np.array([xs[idx], ys[idx]])
        if plane.in_corridor(point, p.plane_influence_m, p.plane_margin_m):
            force = plane_force(point, plane, p.plane_gain, p.plane_influence_m, p.plane_step_m, p.slide_gain)
            u[idx], v[idx] = force
    magnitude = np.hypot(u, v)
    scale = np.where(magnitude > 0, np.log1p(magnitude) / np.maximum(magnitude, 1e-12), 0.0)
    fig, ax = plt.subplots(figsize=(6, 6))
    draw_obstacle(ax)
    ax.plot([plane.e1[0], plane.e2[0]], [plane.e1[1], plane.e2[1]], color="#8e44ad", lw=3)
    ax.quiver(xs, ys, u * scale, v * scale, magnitude, cmap="viridis", angles="xy")
    ax.set(aspect="equal", title="virtual plane force (log-scaled arrows): out, and along")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


RENDERS = (
    ("paper_c_avoid", "vplane"),
    ("paper_c_escape", "vplane"),
    ("paper_c_escape", "apf"),
    ("paper_h_avoid", "vplane"),
    ("paper_h_escape", "vplane"),
)
"""The runs whose renders the pages show: scenario, planner (seed 0)."""


def renders(out: Path) -> None:
    for name, planner in RENDERS:
        scenario = load_scenario(name, [f"planner.name={planner}"])
        result = run_scenario(scenario)
        image = render_top_view(scenario, result.track(), run_caption(result.summary))
        write_png(image, out / f"{name}-{planner}-0.png")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "images")
    out = parser.parse_args().out
    out.mkdir(parents=True, exist_ok=True)
    histogram_figure(out / "method-histogram.png")
    escape_figure(out / "method-escape.png")
    plane_field_figure(out / "method-plane-field.png")
    renders(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
