"""A moving obstacle's `[world.obstacles.motion]` table read into a `geometry.motion.Motion`
(docs/interface.md section 7; docs/scenarios.md, "Moving obstacles").

A cylinder or a box moves when it has a `motion` table, and then has no `center`. The table's
keys: `keyframes` (at least 2 arrays [t_s, x_m, y_m], times from 0 strictly increasing), `loop`
(default true), `interpolation` ("spline", the default, or "linear") and `phase_s` (seconds into
the motion at the run's start, default 0, or "random": drawn from the run's seed, uniform in
[0, the last keyframe's time), a stream of its own per obstacle index).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from vplane_mj.geometry.motion import INTERPOLATIONS, Motion
from vplane_mj.scenario.fields import Field, Invalid, checked, is_finite, is_number, join_key, type_name

MOVING_KINDS = ("cylinder", "box")
"""The obstacle kinds that may have a `motion` table."""
MAX_KEYFRAMES = 10_000
"""The most keyframes a motion may have."""
MAX_MOTION_S = 1e6
"""The latest keyframe time and the largest phase (s): beyond them time has no meaning in a run."""
RANDOM_PHASE = "random"
"""The `phase_s` that draws the phase from the run's seed."""
PHASE_STREAM = 2
"""Second word of a random phase's seed, (seed, 2, obstacle index): a stream apart from the
sensor's (seed) and the odometry's (seed, 1)."""

MOTION_FIELDS = {
    "loop": Field("bool"),
    "interpolation": Field("str", choices=INTERPOLATIONS),
}


def _keyframes(value: Any, key: str, coordinate_limit: float) -> tuple[tuple[float, float, float], ...]:
    """The keyframes array: at least 2 rows [t, x, y] of finite numbers, times from 0 strictly
    increasing, coordinates within +-`coordinate_limit` (m)."""
    if not isinstance(value, list):
        raise Invalid(key, f"must be an array of [t, x, y] arrays, got {type_name(value)}")
    if not 2 <= len(value) <= MAX_KEYFRAMES:
        raise Invalid(key, f"must hold 2 to {MAX_KEYFRAMES} keyframes [t, x, y], got {len(value)}")
    rows: list[tuple[float, float, float]] = []
    for index, row in enumerate(value):
        where = f"{key}[{index}]"
        if not isinstance(row, list) or len(row) != 3:
            got = f"{len(row)} items" if isinstance(row, list) else type_name(row)
            raise Invalid(where, f"must be an array of 3 numbers [t, x, y], got {got}")
        for item, name in zip(row, ("t", "x", "y"), strict=True):
            if not is_number(item):
                raise Invalid(where, f"{name} must be a number, got {type_name(item)}")
            if not is_finite(item):
                raise Invalid(where, f"{name} must be finite, got {item!r}")
        t, x, y = (float(item) for item in row)
        if index == 0 and t != 0.0:
            raise Invalid(where, f"the first keyframe's time must be 0, got {row[0]!r}")
        if index and not t > rows[-1][0]:
            raise Invalid(where, f"times must strictly increase: {row[0]!r} after {rows[-1][0]:g}")
        if t > MAX_MOTION_S:
            raise Invalid(where, f"t must be at most {MAX_MOTION_S:g} s, got {row[0]!r}")
        if max(abs(x), abs(y)) > coordinate_limit:
            raise Invalid(where, f"x and y must lie within +-{coordinate_limit:g} m, got [{x:g}, {y:g}]")
        rows.append((t, x, y))
    return tuple(rows)


def _phase(value: Any, key: str, duration_s: float, seed: int, index: int) -> float:
    """`phase_s` as seconds: a number in [0, MAX_MOTION_S], or RANDOM_PHASE drawn from the seed."""
    if value == RANDOM_PHASE:
        rng = np.random.default_rng((seed, PHASE_STREAM, index))
        return float(rng.uniform(0.0, duration_s))
    if isinstance(value, str):
        raise Invalid(key, f"must be a number of seconds or {RANDOM_PHASE!r}, got {value!r}")
    return checked(value, Field("number", ge=0, le=MAX_MOTION_S), key)


def read_motion(table: Any, path: str, seed: int, index: int, coordinate_limit: float) -> Motion:
    """The `motion` table at `path` of obstacle `index`, its phase resolved with the run's `seed`."""
    if not isinstance(table, dict):
        raise Invalid(path, f"must be a table, got {type_name(table)}")
    unknown = [key for key in table if key not in ("keyframes", "phase_s", *MOTION_FIELDS)]
    if unknown:
        allowed = ", ".join(("keyframes", "loop", "interpolation", "phase_s"))
        raise Invalid(join_key(path, unknown[0]), f"unknown key (allowed here: {allowed})")
    if "keyframes" not in table:
        raise Invalid(join_key(path, "keyframes"), "missing required key")
    keyframes = _keyframes(table["keyframes"], join_key(path, "keyframes"), coordinate_limit)
    options: Mapping[str, Any] = {
        key: checked(table[key], field, join_key(path, key))
        for key, field in MOTION_FIELDS.items()
        if key in table
    }
    phase = _phase(table.get("phase_s", 0.0), join_key(path, "phase_s"), keyframes[-1][0], seed, index)
    return Motion(keyframes, phase_s=phase, **options)
