"""The report of a sweep: success heatmaps, distributions, and a self-contained `bench.html`.

`bench.png`: success per planner and scenario family (an annotated heatmap), times to
goal and path ratios. `bench-scenarios.png`: success per scenario and planner, one row
per scenario, so it stays readable with a hundred scenarios or more. `bench.html`: the
table, both figures and every run, each opening on a click (HTML `<details>`, no script)
to its summary and an SVG picture of its path in its world; the figures are embedded as
data URIs and the page loads nothing, so it works offline and can be mailed around.
"""

from __future__ import annotations

import base64
import html
import io
import json
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, never a window
import matplotlib.pyplot as plt
import numpy as np

from vplane_mj.bench.job import Job
from vplane_mj.bench.sweep import PATH_KEY, TABLE_BASIS, family_of, summarize
from vplane_mj.bench.tables import markdown_table as markdown_table  # kept here for its callers
from vplane_mj.bench.tables import write_table as write_table
from vplane_mj.files import write_atomically, write_csv, write_json
from vplane_mj.geometry import shapes
from vplane_mj.scenario import parse_scenario

_OUTCOME_COLOURS = {"reached": "#1f6fd1", "stuck": "#8e24aa", "timeout": "#e07b00", "error": "#222222"}
PICTURE_MARGIN_M = 1.0
"""A run's picture shows its start, goal and path with this margin (m), within the arena."""
Point = tuple[float, float]
Box = tuple[float, float, float, float]
"""x0, y0, x1, y1 (m)."""
MAX_SCENARIO_ROWS = 40
"""The most scenarios bench-scenarios.png shows, a row each (a taller picture is not read)."""
WorldSymbol = tuple[str, Box, tuple[Point, Point]]
"""A scenario's world as drawn once in the page: its symbol id, its box, its start and goal."""
_RUN_COLUMNS = (
    ("outcome", "outcome"),
    ("time_to_goal_s", "time to goal (s)"),
    ("path_length_m", "path (m)"),
    ("path_ratio", "path ratio"),
    ("collisions", "collisions"),
    ("escapes", "escapes"),
)


@dataclass(frozen=True)
class SuccessGrid:
    """Successes and runs per planner (rows) and column (a scenario or a family)."""

    planners: list[str]
    columns: list[str]
    successes: np.ndarray
    runs: np.ndarray

    @property
    def rates(self) -> np.ndarray:
        """Success rate per cell, NaN where a planner has no run."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.runs > 0, self.successes / np.maximum(self.runs, 1), np.nan)


def success_grid(rows: list[dict], column_of: Callable[[dict], str]) -> SuccessGrid:
    """Count successes per planner and `column_of(row)`, both in first-seen order."""
    planners = list(dict.fromkeys(row["planner"] for row in rows))
    columns = list(dict.fromkeys(column_of(row) for row in rows))
    successes = np.zeros((len(planners), len(columns)), dtype=int)
    runs = np.zeros_like(successes)
    for row in rows:
        i, j = planners.index(row["planner"]), columns.index(column_of(row))
        runs[i, j] += 1
        successes[i, j] += bool(row["success"])
    return SuccessGrid(planners, columns, successes, runs)


def _cell_text(successes: int, runs: int) -> str:
    if runs == 0:
        return ""
    return f"{100 * successes / runs:.0f}%" if runs > 1 else ("yes" if successes else "no")


def _heatmap(axes, grid: SuccessGrid, transpose: bool, fontsize: float) -> None:
    """An annotated success heatmap, red (0%) to green (100%); planners across when transposed."""
    rates = grid.rates
    texts = np.array(
        [
            [_cell_text(successes, runs) for successes, runs in zip(row_successes, row_runs, strict=True)]
            for row_successes, row_runs in zip(grid.successes, grid.runs, strict=True)
        ],
        dtype=object,
    ).reshape(rates.shape)
    if transpose:
        annotated_heatmap(axes, rates.T, texts.T, grid.columns, grid.planners, fontsize=fontsize)
    else:
        annotated_heatmap(axes, rates, texts, grid.planners, grid.columns, fontsize=fontsize, tilt=True)


def annotated_heatmap(
    axes,
    values: np.ndarray,
    texts: np.ndarray,
    row_labels: list[str],
    column_labels: list[str],
    fontsize: float = 9,
    vmin: float = 0.0,
    vmax: float = 1.0,
    cmap: str = "RdYlGn",
    tilt: bool = False,
) -> None:
    """A heatmap of `values` (rows, columns; NaN left blank) with each cell's text written on it,
    white on the dark ends of the colour map; column labels tilted when `tilt`."""
    axes.imshow(np.ma.masked_invalid(values), cmap=cmap, vmin=vmin, vmax=vmax, aspect="auto")
    for i in range(len(row_labels)):
        for j in range(len(column_labels)):
            level = (values[i, j] - vmin) / (vmax - vmin)
            colour = "black" if np.isnan(level) or 0.25 < level < 0.85 else "white"
            axes.text(j, i, texts[i, j], ha="center", va="center", fontsize=fontsize, color=colour)
    axes.set_xticks(
        range(len(column_labels)), column_labels, rotation=30 if tilt else 0, ha="right" if tilt else "center"
    )
    axes.set_yticks(range(len(row_labels)), row_labels, fontsize=fontsize)
    axes.tick_params(length=0)
    axes.set_xticks(np.arange(len(column_labels) + 1) - 0.5, minor=True)
    axes.set_yticks(np.arange(len(row_labels) + 1) - 0.5, minor=True)
    axes.grid(which="minor", color="white", linewidth=1.5)
    axes.tick_params(which="minor", length=0)


def summary_figure(rows: list[dict]) -> plt.Figure:
    """bench.png: success per planner and family, times to goal, path ratios."""
    family = success_grid(rows, lambda row: family_of(row["scenario"]))
    planners = family.planners
    width = max(18.0, 12 + 0.9 * len(family.columns))
    figure, (heat, times, ratios) = plt.subplots(
        1,
        3,
        figsize=(width, 4.8),
        gridspec_kw={"width_ratios": [max(2, len(family.columns)) * 0.8, 4, 4]},
        layout="constrained",
    )
    _heatmap(heat, family, transpose=False, fontsize=9)
    seeds = len({row["seed"] for row in rows})
    heat.set_title(f"success (reached, no collision)\nper planner and family, {seeds} seed(s)")
    data = [[r["time_to_goal_s"] for r in rows if r["planner"] == p and r["reached"]] for p in planners]
    times.boxplot([d if d else [float("nan")] for d in data], tick_labels=planners)
    times.set(ylabel="time to goal (s)", title="time to goal of the runs that reached it")
    data = [[r["path_ratio"] for r in rows if r["planner"] == p and r.get("path_ratio")] for p in planners]
    ratios.boxplot([d if d else [float("nan")] for d in data], tick_labels=planners)
    ratios.set(ylabel="path length / shortest path", title="path ratio of the runs that reached the goal")
    for axes in (times, ratios):  # long planner names stay apart
        axes.tick_params(axis="x", labelrotation=30)
        for label in axes.get_xticklabels():
            label.set_horizontalalignment("right")
    return figure


def scenario_figure(rows: list[dict]) -> plt.Figure:
    """bench-scenarios.png: success per scenario (rows) and planner (columns), annotated; of a
    sweep over more than MAX_SCENARIO_ROWS scenarios, the MAX_SCENARIO_ROWS with the lowest
    success over all planners (bench.csv has every run)."""
    grid = success_grid(rows, lambda row: row["scenario"])
    title = "success per scenario and planner"
    if (scenarios := len(grid.columns)) > MAX_SCENARIO_ROWS:
        grid = _hardest(grid, MAX_SCENARIO_ROWS)
        title = f"the {MAX_SCENARIO_ROWS} of {scenarios} scenarios with the lowest success"
    height = 1.6 + 0.24 * len(grid.columns)
    width = 3.4 + 0.9 * len(grid.planners) + 0.07 * max(len(name) for name in grid.columns)
    figure, axes = plt.subplots(figsize=(width, height), layout="constrained")
    _heatmap(axes, grid, transpose=True, fontsize=8)
    axes.xaxis.tick_top()
    axes.set_title(title, pad=24, fontsize=10)
    return figure


def _hardest(grid: SuccessGrid, count: int) -> SuccessGrid:
    """The `count` columns (scenarios) of least success over every planner, in that order (ties by
    their first-seen order)."""
    rate = grid.successes.sum(axis=0) / np.maximum(grid.runs.sum(axis=0), 1)
    keep = np.argsort(rate, kind="stable")[:count]
    return SuccessGrid(
        grid.planners, [grid.columns[j] for j in keep], grid.successes[:, keep], grid.runs[:, keep]
    )


def png_bytes(figure: plt.Figure) -> bytes:
    """The figure as PNG (100 dpi); the figure is closed."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=100)
    plt.close(figure)
    return buffer.getvalue()


# --------------------------------------------------------------------------- the html page


def write_html_text(
    rows: list[dict],
    table: list[dict],
    scenario_table: list[dict],
    scenario_tomls: dict[str, str],
    figures: dict[str, bytes],
) -> str:
    """The page: `table` per planner, `scenario_table` per scenario and planner,
    `scenario_tomls` maps a row's key to its scenario's TOML text, `figures` a
    title to PNG bytes. Everything is inline; nothing is loaded from anywhere."""
    symbols, symbol_of = _scenario_symbols(rows, scenario_tomls)
    images = "".join(
        f'<figure><img alt="{html.escape(title)}" src="data:image/png;base64,'
        f'{base64.b64encode(data).decode("ascii")}"><figcaption>{html.escape(title)}</figcaption></figure>'
        for title, data in figures.items()
    )
    ordered = sorted(rows, key=lambda row: (row["scenario"], row["planner"], row["seed"]))
    runs = "".join(_run_details(row, symbol_of.get(row["key"])) for row in ordered)
    header = "".join(f"<span>{html.escape(title)}</span>" for _, title in _RUN_COLUMNS)
    planners = ", ".join(dict.fromkeys(row["planner"] for row in rows))
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>vplane-mj bench: {len(rows)} runs</title>
<style>{_CSS}</style></head><body>
<h1>vplane-mj bench: {len(rows)} runs</h1>
<p>{len({r["scenario"] for r in rows})} scenarios, planners {html.escape(planners)}, seed(s)
{html.escape(_seed_text(rows))}. Success means the goal was reached without a collision.</p>
<h2>Per planner</h2>
<p>{html.escape(TABLE_BASIS[0].upper() + TABLE_BASIS[1:])}.</p>
{_table_html(table)}
<h2>Per scenario</h2>
{_table_html(scenario_table)}
<h2>Figures</h2>
{images}
<h2>Every run</h2>
<p>Click a run for its summary and its path (blue: reached, purple: stuck, orange: timeout,
black: error; the green dot is the start, the gold disc the goal).</p>
<svg class="defs" aria-hidden="true">{symbols}</svg>
<div class="runs"><div class="head"><span>scenario</span><span>planner</span><span>seed</span>{header}</div>
{runs}</div>
</body></html>
"""


def _seed_text(rows: list[dict]) -> str:
    """ "0-9" for a range of seeds, else the seeds."""
    seeds = sorted({row["seed"] for row in rows})
    if len(seeds) > 2 and seeds[-1] - seeds[0] == len(seeds) - 1:
        return f"{seeds[0]}-{seeds[-1]}"
    return ", ".join(map(str, seeds))


def _format(value) -> str:
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    return f"{value:.2f}" if isinstance(value, float) else str(value)


def _table_html(table: list[dict]) -> str:
    if not table:
        return "<p>no runs</p>"
    columns = list(table[0])
    head = "".join(f"<th>{html.escape(column)}</th>" for column in columns)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(_format(row.get(c)))}</td>" for c in columns) + "</tr>"
        for row in table
    )
    return f'<table class="planners"><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>'


def _run_details(row: dict, symbol: WorldSymbol | None) -> str:
    """One run: a summary line that opens to the picture and the run's summary."""
    cells = [row["scenario"], row["planner"], str(row["seed"])]
    cells += [_format(row.get(key)) for key, _ in _RUN_COLUMNS]
    line = "".join(f"<span>{html.escape(cell)}</span>" for cell in cells)
    summary = {key: value for key, value in row.items() if key not in ("key", PATH_KEY)}
    text = html.escape(json.dumps(summary, indent=1, allow_nan=False), quote=False)
    css_class = "ok" if row["success"] else "fail"
    return (
        f'<details class="{css_class}"><summary>{line}</summary><div class="run">'
        f"{_run_svg(row, symbol)}<pre>{text}</pre></div></details>\n"
    )


def _run_svg(row: dict, symbol: WorldSymbol | None) -> str:
    """The run's path over its world (a shared symbol per scenario); y points up."""
    if symbol is None:
        return "<p>no picture: the scenario is unknown</p>"
    symbol_id, (x0, y0, x1, y1), ends = symbol
    path = row.get(PATH_KEY) or []
    # Zoom to the start, the goal and the path, within the arena and its walls.
    points = np.array([*ends, *path], dtype=float)
    x0, y0 = np.maximum(points.min(axis=0) - PICTURE_MARGIN_M, (x0, y0))
    x1, y1 = np.minimum(points.max(axis=0) + PICTURE_MARGIN_M, (x1, y1))
    colour = _OUTCOME_COLOURS.get(row["outcome"], "#222222")
    coordinates = " ".join(f"{x:.2f},{-y:.2f}" for x, y in path)  # the path is simplified to 2 cm
    drawn = (
        f'<polyline points="{coordinates}" fill="none" stroke="{colour}" stroke-width="2.5" '
        f'vector-effect="non-scaling-stroke" stroke-linejoin="round"/>'
        if len(path) > 1
        else ""
    )
    if path:
        x, y = path[-1]
        drawn += f'<circle cx="{x:.3f}" cy="{-y:.3f}" r="0.08" fill="{colour}"/>'
    note = "" if path else "<p>no path recorded for this run</p>"
    return (
        f'<svg class="path" viewBox="{x0:.3f} {-y1:.3f} {x1 - x0:.3f} {y1 - y0:.3f}" '
        f'role="img" aria-label="path of the run"><use href="#{symbol_id}"/>{drawn}</svg>{note}'
    )


def _scenario_symbols(
    rows: Iterable[dict], scenario_tomls: dict[str, str]
) -> tuple[str, dict[str, WorldSymbol]]:
    """One SVG symbol per distinct scenario text: floor, obstacles, border, start, goal.

    Returns the symbols' markup and, per row key, (symbol id, the world's box in metres,
    (start, goal)).
    """
    by_text: dict[str, WorldSymbol] = {}
    markup: list[str] = []
    symbol_of: dict[str, WorldSymbol] = {}
    for row in rows:
        text = scenario_tomls.get(row["key"])
        if text is None:
            continue
        if text not in by_text:
            symbol_id = f"world{len(by_text)}"
            body, box, ends = _world_svg(text)
            by_text[text] = (symbol_id, box, ends)
            markup.append(f'<symbol id="{symbol_id}" overflow="visible">{body}</symbol>')
        symbol_of[row["key"]] = by_text[text]
    return "".join(markup), symbol_of


def _world_svg(toml_text: str) -> tuple[str, Box, tuple[Point, Point]]:
    """SVG shapes of a scenario's world (y negated, so that it points up), its box (m) and
    its start and goal."""
    scenario = parse_scenario(toml_text, "bench scenario")
    w, h = scenario.world.size
    pieces = [piece for obstacle in scenario.world.obstacles for piece in obstacle.footprint()]
    if scenario.world.border:
        pieces += list(shapes.border_footprint(scenario.world.size))
    parts = [f'<rect x="0" y="{-h:.3f}" width="{w:.3f}" height="{h:.3f}" fill="#f2f2f2"/>']
    for piece in pieces:
        if isinstance(piece, shapes.Disc):
            parts.append(
                f'<circle cx="{piece.center[0]:.3f}" cy="{-piece.center[1]:.3f}" r="{piece.radius:.3f}" '
                f'fill="#5a5f6e"/>'
            )
        else:
            corners = " ".join(f"{x:.3f},{-y:.3f}" for x, y in piece.corners())
            parts.append(f'<polygon points="{corners}" fill="#5a5f6e"/>')
    robot = scenario.robot
    parts.append(
        f'<circle cx="{robot.goal[0]:.3f}" cy="{-robot.goal[1]:.3f}" r="{robot.goal_tolerance:.3f}" '
        f'fill="#ffbf1a"/>'
    )
    parts.append(f'<circle cx="{robot.start[0]:.3f}" cy="{-robot.start[1]:.3f}" r="0.1" fill="#26bf40"/>')
    margin = 0.3
    return "".join(parts), (-margin, -margin, w + margin, h + margin), (robot.start, robot.goal)


_CSS = """
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.5em; }
table.planners { border-collapse: collapse; }
table.planners th, table.planners td { border: 1px solid #ccc; padding: 3px 8px; text-align: right; }
table.planners td:first-child, table.planners th:first-child { text-align: left; }
figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
svg.defs { position: absolute; width: 0; height: 0; }
.runs { font-variant-numeric: tabular-nums; }
.runs .head, .runs summary { display: grid; grid-template-columns: 16em 6em 4em 6em repeat(5, 8em);
  gap: 0 0.5em; padding: 2px 4px; }
.runs .head { font-weight: bold; border-bottom: 1px solid #999; }
.runs summary { cursor: pointer; list-style: none; }
.runs summary::-webkit-details-marker { display: none; }
.runs details:nth-child(even) summary { background: #f6f6f6; }
.runs details.fail summary span:nth-child(4) { color: #b00020; }
.runs details[open] summary { background: #e3ecfa; }
.run { display: flex; gap: 1em; align-items: flex-start; padding: 0.5em 0 1em 1em; }
.run svg.path { width: 360px; height: 360px; border: 1px solid #ccc; background: white; flex: none; }
.run pre { margin: 0; font-size: 12px; max-height: 360px; overflow: auto; }
"""


def write_outputs(rows: list[dict], table: list[dict], out_dir: Path, jobs: list[Job]) -> list[Path]:
    """bench.csv (one row per run), bench.json (rows, table, table per scenario), the figures and
    bench.html."""
    columns = sorted({key for row in rows for key in row if not isinstance(row[key], dict | list)})
    scenario_table = summarize(rows, by_scenario=True)
    written = [
        write_csv(out_dir / "bench.csv", rows, columns),
        write_json(
            out_dir / "bench.json",
            {"format": 1, "rows": rows, "table": table, "scenario_table": scenario_table},
        ),
    ]
    figures = {
        "bench.png": png_bytes(summary_figure(rows)),
        "bench-scenarios.png": png_bytes(scenario_figure(rows)),
    }
    for name, data in figures.items():
        written.append(write_atomically(out_dir / name, partial(Path.write_bytes, data=data)))
    page = write_html_text(
        rows,
        table,
        scenario_table,
        {job.key: job.toml for job in jobs},
        {
            "success per planner and family, times to goal, path ratios": figures["bench.png"],
            "success per scenario and planner": figures["bench-scenarios.png"],
        },
    )
    written.append(
        write_atomically(out_dir / "bench.html", lambda tmp: tmp.write_text(page, encoding="utf-8"))
    )
    return written
