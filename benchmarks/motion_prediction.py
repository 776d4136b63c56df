"""How far DynaBARN's obstacles stray from the motion a tracker predicts for them.

Every planner that evades moving obstacles here predicts each one from its track: where it is
and its velocity, held (a constant-velocity prediction, `planning.motion.evasion`). This script
measures that prediction on the obstacles' true motions, as a perfect tracker would make it:
for worlds generated as `vplane-mj generate dynabarn` does (`--count`, seed `--world-seed`, the
thirds as in benchmarks/dynabarn.py), each obstacle is sampled every `--step` seconds over
`--span` seconds of its loop; from every `--stride` seconds on, its velocity is the least-squares
line through its last `--window` seconds of true positions, and the prediction from its true
position is set against where it really is `--horizons` seconds later (windows over a loop's jump
back to its start are left out). The error is split along the predicted direction (the obstacle
went faster or slower) and across it (it turned). Beside it, a constant-turn-rate prediction
(speed, heading and turn rate from a quadratic fit over the same window) shows whether a model
of the turns would predict better.

Prints per third and horizon: the predictions scored, the constant-velocity error's median and
90th percentile (m), the 90th percentiles of its parts along and across, and the constant-turn
prediction's 90th percentile; writes `OUT/motion_prediction.csv` and `.md`.

    python benchmarks/motion_prediction.py [--count 60] [--world-seed 0] [--out DIR]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.tables import formatted, markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.geometry.motion import MotionTable
from vplane_mj.scenario import parse_document
from vplane_mj.worlds.dynabarn_generate import generate_dynabarn
from vplane_mj.worlds.dynabarn_layout import DIFFICULTIES

JUMP_M = 0.5
"""A step longer than this (m) between two samples is a loop's jump back to its start (an
obstacle at 3 m/s moves 0.15 m in a 0.05 s step)."""
COLUMNS = (
    "third",
    "horizon_s",
    "predictions",
    "error_median_m",
    "error_p90_m",
    "along_p90_m",
    "across_p90_m",
    "turn_model_error_p90_m",
)


def prediction_errors(
    positions: np.ndarray, step_s: float, window_s: float, stride_s: float, horizons_s: tuple[float, ...]
) -> np.ndarray:
    """(K, H, 4) for one obstacle's true positions (T, 2; m) sampled every `step_s` s: per
    prediction made every `stride_s` s from a `window_s` s window of its past, and per horizon
    of `horizons_s` (s), the constant-velocity prediction's error (m), its parts along and
    across the predicted direction (m, signed along: positive when the obstacle got farther),
    and the constant-turn-rate prediction's error (m) (module docstring)."""
    back = round(window_s / step_s)
    ahead = [round(h / step_s) for h in horizons_s]
    jumped = np.concatenate(([False], np.hypot(*np.diff(positions, axis=0).T) > JUMP_M))
    times = np.arange(-back, 1) * step_s
    rows = []
    for k in range(back, len(positions) - max(ahead), max(1, round(stride_s / step_s))):
        if jumped[k - back + 1 : k + max(ahead) + 1].any():
            continue
        past = positions[k - back : k + 1]
        velocity = np.polyfit(times, past, 1)[0]
        quadratic = np.polyfit(times, past, 2)
        rows.append([_errors(positions[k], velocity, quadratic, positions[k + n], n * step_s) for n in ahead])
    return np.array(rows).reshape(-1, len(horizons_s), 4)


def _errors(
    now: np.ndarray, velocity: np.ndarray, quadratic: np.ndarray, truth: np.ndarray, horizon_s: float
) -> list[float]:
    """The errors of `prediction_errors` for one prediction from `now` (m) over `horizon_s` (s):
    constant `velocity` (m/s), and a constant turn rate from the `quadratic` fit (3, 2: the
    coefficients, highest power first, of x and y over time; its value at time 0 is now)."""
    miss = truth - (now + velocity * horizon_s)
    speed = float(np.hypot(*velocity))
    along_unit = velocity / speed if speed > 1e-9 else np.array([1.0, 0.0])
    along = float(miss @ along_unit)
    across = float(miss @ np.array([-along_unit[1], along_unit[0]]))
    tangent, accel = quadratic[1], 2.0 * quadratic[0]
    turn_speed = float(np.hypot(*tangent))
    turn = (tangent[0] * accel[1] - tangent[1] * accel[0]) / max(turn_speed**2, 1e-9)
    heading = math.atan2(tangent[1], tangent[0])
    if abs(turn) > 1e-6:
        swept = heading + turn * horizon_s
        offset = (
            turn_speed
            / turn
            * np.array([math.sin(swept) - math.sin(heading), math.cos(heading) - math.cos(swept)])
        )
    else:
        offset = tangent * horizon_s
    return [float(np.hypot(*miss)), along, across, float(np.hypot(*(truth - now - offset)))]


def world_errors(document: dict, args: argparse.Namespace, horizons_s: tuple[float, ...]) -> np.ndarray:
    """(K, H, 4) `prediction_errors` of every obstacle of one generated world."""
    scenario = parse_document(document, f"{document['name']}.toml")
    table = MotionTable([moving.motion for moving in scenario.world.moving])
    samples = np.stack([table.positions(t) for t in np.arange(0.0, args.span, args.step)], axis=1)
    found = [prediction_errors(track, args.step, args.window, args.stride, horizons_s) for track in samples]
    return np.concatenate(found) if found else np.empty((0, len(horizons_s), 4))


def table_rows(third: str, errors: np.ndarray, horizons_s: tuple[float, ...]) -> list[dict]:
    """The rows of one third (`errors` as `prediction_errors` gives them), one per horizon."""
    return [
        {
            "third": third,
            "horizon_s": horizon,
            "predictions": len(errors),
            "error_median_m": float(np.median(errors[:, h, 0])),
            "error_p90_m": float(np.percentile(errors[:, h, 0], 90)),
            "along_p90_m": float(np.percentile(np.abs(errors[:, h, 1]), 90)),
            "across_p90_m": float(np.percentile(np.abs(errors[:, h, 2]), 90)),
            "turn_model_error_p90_m": float(np.percentile(errors[:, h, 3], 90)),
        }
        for h, horizon in enumerate(horizons_s)
    ]


def check_spans(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Refuse (argparse's error, exit 2) a window or stride shorter than the step, or a span too
    short for the window and the longest horizon."""
    for option in ("window", "stride"):
        if getattr(args, option) < args.step:
            parser.error(
                f"argument --{option}: at least --step ({args.step:g} s), not {getattr(args, option):g}"
            )
    if not args.span > args.window + max(args.horizons) + args.step:
        parser.error(
            f"argument --span: longer than --window and the longest horizon together, not {args.span:g}"
        )


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--count", type=options.whole(1), default=60, help="worlds, split into the three thirds"
    )
    parser.add_argument("--world-seed", type=options.whole(0), default=0, help="seed of the worlds")
    parser.add_argument(
        "--horizons",
        type=options.positives,
        default="0.5,1,2,3",
        help="seconds ahead, comma-separated",
    )
    parser.add_argument(
        "--window", type=options.positive, default=0.5, help="seconds of the past a velocity is fit to"
    )
    parser.add_argument("--span", type=options.positive, default=60.0, help="seconds of each loop sampled")
    parser.add_argument("--step", type=options.positive, default=0.05, help="seconds between samples")
    parser.add_argument("--stride", type=options.positive, default=0.25, help="seconds between predictions")
    parser.add_argument("--out", type=Path, default=Path("logs/motion_prediction"))
    args = parser.parse_args(argv)
    check_spans(parser, args)
    horizons = tuple(args.horizons)
    out = prepare_out_dir(args.out)
    cases = generate_dynabarn(args.count, args.world_seed)
    per_third = {
        third: [world_errors(case.document, args, horizons) for case in cases if f"_{third}_" in case.name]
        for third in DIFFICULTIES
    }
    found = {**per_third, "all": [errors for worlds in per_third.values() for errors in worlds]}
    table = [
        row
        for third, errors in found.items()
        if sum(len(e) for e in errors)
        for row in table_rows(third, np.concatenate(errors), horizons)
    ]
    text = markdown_table(table, COLUMNS, formatted({key: ".2f" for key in COLUMNS[3:]}))
    written = write_table(out, "motion_prediction", table, COLUMNS, text)
    print(text)
    print("\n".join(f"wrote {path}" for path in written))
    return 0


if __name__ == "__main__":
    sys.exit(main())
