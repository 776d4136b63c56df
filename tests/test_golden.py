"""Golden trajectories: every planner on the trap suite, the paper scenarios and a few generated
worlds drives the trajectory recorded in `golden_digests.json`, bit for bit.

Each run is cut at `GOLDEN_TIME_LIMIT_S` simulated seconds, so the digest covers the trajectory
up to there (or to the goal, or to the planner giving up). A change to the code that is meant to
leave behaviour alone must leave every recorded value as it is; a change that is meant to alter
behaviour is recorded again, from the repository's root, with

    python -m tests.test_golden --record

Floating-point results depend on the MuJoCo and numpy builds and on the vector instructions
numpy finds on the CPU (with AVX-512 it computes sines, arctangents and the like by other
routines, which differ in the last bit): the file keeps the environment it was recorded in,
and the test is skipped in others (record again there to use it).
"""

from __future__ import annotations

import json
import platform
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import mujoco
import numpy as np
import pytest

from vplane_mj.planning.registry import PLANNERS
from vplane_mj.scenario import load_scenario, parse_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.worlds.families import generate, trap_suite

GOLDEN = Path(__file__).with_name("golden_digests.json")
GOLDEN_TIME_LIMIT_S = 40.0
"""Simulated seconds at most per run (s)."""
PAPER = ("paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape")
GENERATED = (("barn", 2, 1), ("clutter", 2, 1), ("corridors", 2, 1))
"""(family, count, seed) of the generated worlds."""
RECORDED_KEYS = ("outcome", "trajectory_sha256", "collisions", "local_minima", "escapes")
"""The summary keys kept per run: the trajectory's digest and what the run made of it."""


def environment() -> dict[str, str]:
    """What the digests depend on besides the code."""
    return {
        "mujoco": mujoco.__version__,
        "numpy": np.__version__,
        "machine": platform.machine(),
        "numpy_simd": ",".join(numpy_dispatch_targets()),
    }


def numpy_dispatch_targets() -> list[str]:
    """The optimised code paths numpy chose on this CPU (e.g. X86_V3, X86_V4, AVX512_SKX)."""
    try:
        from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    except ImportError:  # numpy before 2.0 (another environment than the recorded one anyway)
        return ["unknown"]
    return [target for target in __cpu_dispatch__ if __cpu_features__.get(target)]


def worlds() -> list[tuple[str, str]]:
    """(name, TOML text) of every world: the trap suite, the paper scenarios, the generated ones."""
    found = [(case.name, case.toml()) for case in trap_suite()]
    found += [(name, load_scenario(name).to_toml()) for name in PAPER]
    for family, count, seed in GENERATED:
        found += [(case.name, case.toml()) for case in generate(family, count, seed)]
    return found


def _run(job: tuple[str, str, str]) -> tuple[str, dict]:
    name, toml, planner = job
    overrides = [f"planner.name={planner}", f"run.time_limit_s={GOLDEN_TIME_LIMIT_S}"]
    summary = run_scenario(parse_scenario(toml, name, overrides)).summary
    return f"{name}|{planner}", {key: getattr(summary, key) for key in RECORDED_KEYS}


def run_all() -> dict[str, dict]:
    """Every planner on every world, in a pool of two processes: run name -> recorded keys."""
    jobs = [(name, toml, planner) for name, toml in worlds() for planner in sorted(PLANNERS)]
    with ProcessPoolExecutor(max_workers=2) as pool:
        return dict(sorted(pool.map(_run, jobs)))


def test_every_planner_drives_its_recorded_trajectories():
    golden = json.loads(GOLDEN.read_text(encoding="utf-8"))
    if golden["environment"] != environment():
        pytest.skip(f"recorded with {golden['environment']}, this is {environment()}")
    assert golden["time_limit_s"] == GOLDEN_TIME_LIMIT_S
    runs = run_all()
    assert runs.keys() == golden["runs"].keys()
    changed = [
        f"{run}: {key} {golden['runs'][run][key]} -> {values[key]}"
        for run, values in runs.items()
        for key in RECORDED_KEYS
        if values[key] != golden["runs"][run][key]
    ]
    assert not changed, f"{len(changed)} recorded values changed:\n" + "\n".join(changed)


def record() -> None:
    """Run everything and write the golden file."""
    document = {"environment": environment(), "time_limit_s": GOLDEN_TIME_LIMIT_S, "runs": run_all()}
    GOLDEN.write_text(json.dumps(document, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {GOLDEN}: {len(document['runs'])} runs")


if __name__ == "__main__":
    if sys.argv[1:] != ["--record"]:
        raise SystemExit("usage: python -m tests.test_golden --record")
    record()
