"""Golden runs: every planner on the trap suite, the paper scenarios and a few generated worlds
makes of each world what `golden_digests.json` records.

Each run is cut at `GOLDEN_TIME_LIMIT_S` simulated seconds. Where the environment matches the
one the file was recorded in (`environment`): the MuJoCo, numpy and numba builds, the
architecture, whether numpy computes sines, arctangents and the like by its AVX-512 routines
(which may differ in the last bit), the CPU model the kernels are compiled for (`generic`
unless NUMBA_CPU_NAME chooses one) and what the C library's mathematical functions return
(MuJoCo, the kernels and numpy call them), every run is compared exactly: its trajectory by its
digest, bit for bit, and its outcome, collisions, local minima, escapes and path length. No
product in a run goes through BLAS, so the kernels OpenBLAS picks for a CPU are not among them
(docs/contributing.md says what was measured).

Elsewhere a last bit that differs grows, in a run that grinds along a wall or dithers in a
trap, into another path; so there each run is held to what does not hang on last bits: whether
it succeeds (reaches its goal without a collision), and for a success its counts exactly and
its path length to `PATH_RTOL`. A skipped test says that the rest was left out and
why.

A change to the code that is meant to leave behaviour alone must leave every recorded value
as it is; a change that is meant to alter behaviour is recorded again, from the repository's
root, with

    python -m tests.test_golden --record
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
import os
import platform
import struct
import subprocess
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import mujoco
import numba
import numpy as np
import pytest

from vplane_mj.kernels import compiled_for_cpu
from vplane_mj.planning.protocol.registry import BUILT_IN
from vplane_mj.scenario import load_scenario, parse_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.worlds.families import generate, trap_suite

GOLDEN = Path(__file__).with_name("golden_digests.json")
GOLDEN_TIME_LIMIT_S = 40.0
"""Simulated seconds at most per run (s)."""
PAPER = ("paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape")
GENERATED = (("barn", 2, 1), ("clutter", 2, 1), ("corridors", 2, 1))
"""(family, count, seed) of the generated worlds."""
PLANNERS = sorted(BUILT_IN)
"""The package's own planners (one installed from elsewhere has no recorded runs)."""
EXACT_KEYS = ("outcome", "collisions", "local_minima", "escapes")
"""What a run made of its world, compared exactly (in another environment, for its successes)."""
PATH_KEY = "path_length_m"
PATH_RTOL = 0.02
"""Relative tolerance of a successful run's path length in another environment (with glibc's
builds of its mathematical functions for CPUs without fused multiply-adds, every trajectory's
last bits changed and the successes' lengths by up to 0.7%)."""
DIGEST_KEY = "trajectory_sha256"
RECORDED_KEYS = ("outcome", DIGEST_KEY, "collisions", "local_minima", "escapes", PATH_KEY)
"""The summary keys kept per run."""


@functools.cache
def environment() -> dict[str, str]:
    """What the digests depend on besides the code."""
    return {
        "mujoco": mujoco.__version__,
        "numpy": np.__version__,
        "numba": numba.__version__,
        "machine": platform.machine(),
        "numpy_avx512": "yes" if _cpu_features().get("X86_V4") else "no",
        "kernels_cpu": compiled_for_cpu(),
        "libm": libm(),
    }


def libm() -> str:
    """The C library and a digest of what its `sin`, `cos`, `tan`, `exp`, `atan` and `atan2`
    return on 65,537 fixed arguments (Python's math module calls them): builds of one version
    differ in last bits (glibc picks other code for a CPU with fused multiply-adds)."""
    name, version = platform.libc_ver()
    count = 65537
    arguments = [-40.0 + 80.0 * k / count for k in range(count)]
    digest = hashlib.sha256()
    for function in (math.sin, math.cos, math.tan, math.exp, math.atan):
        digest.update(struct.pack(f"{count}d", *map(function, arguments)))
    digest.update(struct.pack(f"{count}d", *(math.atan2(x, 1.7) for x in arguments)))
    return f"{name or 'unknown'} {version}, results {digest.hexdigest()[:16]}"


def _cpu_features() -> dict[str, bool]:
    """What numpy found the CPU to have, its dispatch targets among them (X86_V4: its AVX-512
    routines); empty where it cannot say (numpy before 2.0)."""
    try:
        from numpy._core._multiarray_umath import __cpu_features__
    except ImportError:
        return {}
    return dict(__cpu_features__)


def worlds() -> list[tuple[str, str]]:
    """(name, TOML text) of every world: the trap suite, the paper scenarios, the generated ones."""
    found = [(case.name, case.toml()) for case in trap_suite()]
    found += [(name, load_scenario(name).to_toml()) for name in PAPER]
    for family, count, seed in GENERATED:
        found += [(case.name, case.toml()) for case in generate(family, count, seed)]
    return found


@functools.cache
def world_texts() -> dict[str, str]:
    """Every world's TOML text by name (made once per process)."""
    return dict(worlds())


@functools.cache
def golden() -> dict:
    """The golden file: its environment, time limit and runs ("world|planner" -> recorded keys)."""
    return json.loads(GOLDEN.read_text(encoding="utf-8"))


def digests_compared() -> bool:
    """Whether this is the environment the golden file was recorded in."""
    return golden()["environment"] == environment()


def _run(job: tuple[str, str, str]) -> tuple[str, dict]:
    name, toml, planner = job
    overrides = [f"planner.name={planner}", f"run.time_limit_s={GOLDEN_TIME_LIMIT_S}"]
    summary = run_scenario(parse_scenario(toml, name, overrides)).summary
    return f"{name}|{planner}", {key: getattr(summary, key) for key in RECORDED_KEYS}


def run_all() -> dict[str, dict]:
    """Every planner on every world, in a pool of two processes: run name -> recorded keys."""
    jobs = [(name, toml, planner) for name, toml in worlds() for planner in PLANNERS]
    with ProcessPoolExecutor(max_workers=2) as pool:
        return dict(sorted(pool.map(_run, jobs)))


def succeeded(values: dict) -> bool:
    """Whether a run reached its goal without a collision."""
    return values["outcome"] == "reached" and values["collisions"] == 0


def changes(run: str, values: dict, recorded: dict) -> list[str]:
    """How a run's values differ from the recorded ones: all of them where the environment
    matches; elsewhere its success, and for a success its counts and path length."""
    if digests_compared():
        keys, rtol = [key for key in (*EXACT_KEYS, DIGEST_KEY) if values[key] != recorded[key]], 0.0
    elif succeeded(values) != succeeded(recorded):
        keys, rtol = ["outcome", "collisions"], math.inf
    elif succeeded(recorded):
        keys = [key for key in EXACT_KEYS if values[key] != recorded[key]]
        rtol = PATH_RTOL
    else:
        keys, rtol = [], math.inf
    if not math.isclose(values[PATH_KEY], recorded[PATH_KEY], rel_tol=rtol):
        keys.append(PATH_KEY)
    return [f"{run}: {key} {recorded[key]!r} -> {values[key]!r}" for key in keys]


@pytest.fixture(scope="module")
def pool():
    """Two processes that run a world's planners side by side."""
    with ProcessPoolExecutor(max_workers=2) as executor:
        yield executor


RECORDED_SUCCESS = {
    "outcome": "reached",
    "collisions": 0,
    "local_minima": 1,
    "escapes": 1,
    PATH_KEY: 10.0,
    DIGEST_KEY: "a",
}
RECORDED_FAILURE = {**RECORDED_SUCCESS, "outcome": "stuck", "collisions": 40, "escapes": 0}


@pytest.fixture
def elsewhere(monkeypatch):
    """Compare as in an environment other than the recorded one."""
    monkeypatch.setattr(sys.modules[__name__], "digests_compared", lambda: False)


@pytest.mark.parametrize(
    "values",
    [
        {**RECORDED_FAILURE, "outcome": "timeout", "collisions": 3, PATH_KEY: 6.0, DIGEST_KEY: "b"},
        {**RECORDED_FAILURE, "outcome": "reached", "collisions": 12, DIGEST_KEY: "b"},
    ],
)
def test_elsewhere_a_run_that_failed_may_fail_another_way(values, elsewhere):
    assert changes("w|p", values, RECORDED_FAILURE) == []


def test_elsewhere_a_success_keeps_its_counts_and_nearly_its_length(elsewhere):
    assert changes("w|p", {**RECORDED_SUCCESS, PATH_KEY: 10.15, DIGEST_KEY: "b"}, RECORDED_SUCCESS) == []
    assert changes("w|p", {**RECORDED_SUCCESS, PATH_KEY: 10.3}, RECORDED_SUCCESS) == [
        "w|p: path_length_m 10.0 -> 10.3"
    ]
    assert changes("w|p", {**RECORDED_SUCCESS, "escapes": 2}, RECORDED_SUCCESS) == ["w|p: escapes 1 -> 2"]
    assert changes("w|p", RECORDED_FAILURE, RECORDED_SUCCESS) == [
        "w|p: outcome 'reached' -> 'stuck'",
        "w|p: collisions 0 -> 40",
    ]
    assert changes("w|p", RECORDED_SUCCESS, RECORDED_FAILURE) != []


def test_where_the_environment_matches_every_bit_counts(monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "digests_compared", lambda: True)
    assert changes("w|p", {**RECORDED_FAILURE, DIGEST_KEY: "b"}, RECORDED_FAILURE) == [
        "w|p: trajectory_sha256 'a' -> 'b'"
    ]
    assert changes("w|p", {**RECORDED_FAILURE, PATH_KEY: 10.001}, RECORDED_FAILURE) == [
        "w|p: path_length_m 10.0 -> 10.001"
    ]


@pytest.mark.slow
def test_the_golden_file_holds_every_planner_on_every_world():
    document = golden()
    assert document["time_limit_s"] == GOLDEN_TIME_LIMIT_S
    assert document["runs"].keys() == {f"{name}|{planner}" for name in world_texts() for planner in PLANNERS}
    assert all(tuple(values) == RECORDED_KEYS for values in document["runs"].values())


@pytest.mark.slow
def test_trajectory_digests_are_compared_on_this_machine():
    if not digests_compared():
        pytest.skip(
            f"trajectories not compared bit for bit: recorded with {golden()['environment']}, "
            f"this is {environment()}; each run's success is, and a success's counts and path length"
        )


@pytest.mark.slow
@pytest.mark.parametrize("world", sorted({run.partition("|")[0] for run in golden()["runs"]}))
def test_every_planner_drives_its_recorded_runs(world, pool):
    jobs = [(world, world_texts()[world], planner) for planner in PLANNERS]
    runs = golden()["runs"]
    changed = [change for run, values in pool.map(_run, jobs) for change in changes(run, values, runs[run])]
    assert not changed, f"{len(changed)} recorded values changed:\n" + "\n".join(changed)


ANOTHER_LIBM = "glibc.cpu.hwcaps=-AVX2,-FMA,-FMA4"
"""GLIBC_TUNABLES that have glibc pick the builds of its mathematical functions for a CPU
without fused multiply-adds: another machine's libm, here."""


@pytest.mark.slow
def test_with_another_libm_every_run_holds_what_last_bits_leave_alone():
    # Every trajectory's last bits change under another libm; the suite must skip the digests,
    # naming both environments, and pass on the rest (not fail, as it did when the fingerprint
    # named the library's version instead of what its functions return).
    root = Path(__file__).parents[1]
    env = {**os.environ, "GLIBC_TUNABLES": ANOTHER_LIBM}
    probe = [sys.executable, "-c", "from tests.test_golden import libm; print(libm())"]
    other = subprocess.run(probe, capture_output=True, text=True, env=env, cwd=root, timeout=60)
    if other.stdout.strip() == libm():
        pytest.skip(f"GLIBC_TUNABLES={ANOTHER_LIBM} leaves this C library's results as they are")
    suite = [sys.executable, "-m", "pytest", "-q", "-rs", "-m", "slow", "-o", "addopts=", __file__]
    suite += ["-k", "not another_libm"]
    finished = subprocess.run(suite, capture_output=True, text=True, env=env, cwd=root, timeout=900)
    assert finished.returncode == 0, finished.stdout[-3000:]
    assert "1 skipped" in finished.stdout and "trajectories not compared bit for bit" in finished.stdout


def record() -> None:
    """Run everything and write the golden file."""
    document = {"environment": environment(), "time_limit_s": GOLDEN_TIME_LIMIT_S, "runs": run_all()}
    GOLDEN.write_text(json.dumps(document, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {GOLDEN}: {len(document['runs'])} runs")


if __name__ == "__main__":
    if sys.argv[1:] != ["--record"]:
        raise SystemExit("usage: python -m tests.test_golden --record")
    record()
