"""Planners from outside the package: the example planner through `run`, `bench` and `list`,
registration in code and by installed entry points, and the rule that a scenario file never
makes anything be imported."""

from __future__ import annotations

import json
import multiprocessing
import os
import re
import shlex
import subprocess
import sys
import textwrap
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from vplane_mj.bench.sweep import plan_jobs, run_job
from vplane_mj.errors import ScenarioError, VPlaneError
from vplane_mj.planning import (
    DetectorParams,
    Observation,
    Planner,
    PlannerError,
    PlannerParams,
    load_planner,
    param,
    register_planner,
)
from vplane_mj.planning.protocol.plugins import canonical_spec
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.sim.loop import run_scenario
from vplane_mj.sweeps import sweep

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "random_walk_planner.py"
EXAMPLE_SPEC = f"{EXAMPLE}:RandomWalkPlanner"

SIDE_EFFECT_MODULE = """
from pathlib import Path
Path("imported.marker").write_text("imported")  # the import itself leaves a trace

from vplane_mj.planning import Decision, Planner

class Evil(Planner):
    name = "evil"
    summary = citation = "imports itself"

    def step(self, obs):
        return Decision(force=obs.goal - obs.position, mode="normal")
"""

OPEN_FIELD = """
format = 1
name = "from_a_file"
[world]
size = [5.0, 5.0]
[robot]
start = [1.0, 1.0]
goal = [4.0, 4.0]
[planner]
name = "{planner}"
"""


def vplane_mj(*args: str, cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    """`python -m vplane_mj ARGS` in a fresh process, in `cwd`."""
    return subprocess.run(
        [sys.executable, "-m", "vplane_mj", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )


# -- a scenario file is data: it never imports ----------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("planner", ["os:system", "side_effect:Evil", "./side_effect.py:Evil"])
def test_a_scenario_file_naming_a_class_is_refused_and_imports_nothing(tmp_path, planner):
    (tmp_path / "side_effect.py").write_text(SIDE_EFFECT_MODULE)
    (tmp_path / "attack.toml").write_text(OPEN_FIELD.format(planner=planner))
    probe = (
        "import sys\nfrom vplane_mj.cli import main\nstatus = main(sys.argv[1:])\n"
        "print(status, 'side_effect' in sys.modules, any('side_effect' in m for m in sys.modules))"
    )
    for command in (["check", "attack.toml"], ["run", "attack.toml", "--out", "out"]):
        done = subprocess.run(
            [sys.executable, "-c", probe, *command], cwd=tmp_path, capture_output=True, text=True, timeout=120
        )
        assert done.stdout.split("\n")[-2] == "2 False False", done.stdout + done.stderr
        expected = f"error: attack.toml: planner.name: unknown planner '{planner}'; available: apf, "
        assert done.stderr.startswith(expected), done.stderr
        assert "imported only when named on the command line (--planner module:Class)" in done.stderr
        assert "Traceback" not in done.stderr
    assert not (tmp_path / "imported.marker").exists()
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_set_planner_name_to_a_class_is_refused_too(tmp_path):
    (tmp_path / "side_effect.py").write_text(SIDE_EFFECT_MODULE)
    done = vplane_mj("run", "open_field", "--set", "planner.name=side_effect:Evil", cwd=tmp_path)
    assert done.returncode == 2 and "planner.name: unknown planner 'side_effect:Evil'" in done.stderr
    assert not (tmp_path / "imported.marker").exists()


def test_the_command_line_imports_a_module_from_the_current_directory(tmp_path):
    (tmp_path / "side_effect.py").write_text(SIDE_EFFECT_MODULE)
    args = ["--no-render", "--no-log", "--set", "run.time_limit_s=3", "--out", "out"]
    done = vplane_mj("run", "open_field", "--planner", "side_effect:Evil", *args, cwd=tmp_path)
    assert done.returncode == 1, done.stderr  # 3 s are too short to reach the goal
    assert (tmp_path / "imported.marker").exists()
    summary = json.loads((tmp_path / "out" / "open_field-evil-0.json").read_text())
    assert summary["planner"] == "evil" and summary["outcome"] == "timeout" and summary["path_length_m"] > 0.5


@pytest.mark.parametrize(
    ("spec", "reason"),
    [
        ("no_such_module:Planner", "cannot import no_such_module: ModuleNotFoundError"),
        ("side_effect:Missing", "side_effect has no Missing"),
        ("os:path", "os:path: it is not a subclass of vplane_mj.planning.Planner"),
        ("missing/file.py:Planner", "no such file"),
        (
            "./notes.txt:Planner",
            "cannot import ./notes.txt: ImportError: notes.txt is not a Python source file",
        ),
        ("bad_name:Bad", "its name must match [a-z0-9_]+ (it names output files), got 'Bad-Name'"),
        ("clash:Clash", "its name 'apf' is a built-in planner's"),
    ],
)
def test_a_bad_planner_class_on_the_command_line_is_exit_2_with_the_reason(tmp_path, spec, reason):
    (tmp_path / "side_effect.py").write_text(SIDE_EFFECT_MODULE)
    (tmp_path / "bad_name.py").write_text(
        SIDE_EFFECT_MODULE.replace('"evil"', '"Bad-Name"').replace("Evil", "Bad")
    )
    (tmp_path / "clash.py").write_text(SIDE_EFFECT_MODULE.replace('"evil"', '"apf"').replace("Evil", "Clash"))
    (tmp_path / "notes.txt").write_text(SIDE_EFFECT_MODULE)
    done = vplane_mj("run", "open_field", "--planner", spec, "--out", "out", cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith(f"error: --planner: {spec}: ") and reason in done.stderr, done.stderr
    assert "Traceback" not in done.stderr and not (tmp_path / "out").exists()


# -- the example planner through the command line ----------------------------------------------


@pytest.mark.slow
def test_bench_runs_the_example_beside_a_built_in_planner_and_resumes(tmp_path):
    spec = os.path.relpath(EXAMPLE, tmp_path) + ":RandomWalkPlanner"  # a relative path, as users type
    args = ["bench", "paper_c_escape", "--planners", f"apf,{spec}", "--seeds", "0-1", "--jobs", "2"]
    args += ["--set", "sensors.noise_std=0.01", "--set", "run.time_limit_s=80", "--out", "out"]
    done = vplane_mj(*args, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "out" / "bench.json").read_text())
    rows = {(row["planner"], row["seed"]): row for row in report["rows"]}
    assert sorted(rows) == [("apf", 0), ("apf", 1), ("random_walk", 0), ("random_walk", 1)]
    assert all(row["outcome"] in ("reached", "stuck", "timeout") for row in rows.values())
    assert all(rows[("apf", seed)]["outcome"] == "stuck" for seed in (0, 1))  # APF has no escape
    walks = [rows[("random_walk", seed)] for seed in (0, 1)]
    assert all(row["local_minima"] >= 1 and row["escapes"] >= 1 for row in walks)  # it walked out
    assert any(row["reached"] for row in walks)
    assert all(row["planner_params"]["walk_s"] == 10.0 for row in walks)
    assert [row["planner"] for row in report["table"]] == ["apf", "random_walk"]
    assert "random_walk" in done.stdout and (tmp_path / "out" / "bench.html").exists()

    again = vplane_mj(*args, cwd=tmp_path)  # the journal's keys name the planner: nothing to redo
    assert again.returncode == 0 and "4 runs: 4 already done, 0 to run" in again.stderr


@pytest.mark.slow
def test_run_names_outputs_by_the_class_name_and_the_log_replays_without_it(tmp_path):
    args = ["--set", "planner.walk_s=12", "--set", "run.time_limit_s=60", "--no-render", "--out", "out"]
    done = vplane_mj("run", "paper_c_escape", "--planner", EXAMPLE_SPEC, *args, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "out" / "paper_c_escape-random_walk-0.json").read_text())
    assert summary["planner"] == "random_walk" and summary["planner_params"]["walk_s"] == 12.0
    assert summary["reached"] and summary["escapes"] >= 1
    # The log's own commands read it in a process where the planner is not registered.
    replayed = vplane_mj("summary", "out/paper_c_escape-random_walk-0.mcap", cwd=tmp_path)
    assert replayed.returncode == 0 and "agrees with the run's stored summary" in replayed.stdout


@pytest.mark.slow
def test_set_and_list_work_for_a_class_named_on_the_command_line(tmp_path):
    bad = vplane_mj("run", "open_field", "--planner", EXAMPLE_SPEC, "--set", "planner.walk_z=3", cwd=tmp_path)
    assert bad.returncode == 2
    assert bad.stderr.startswith(
        "error: --set planner.walk_z: not a parameter of planner 'random_walk' (attract_gain,"
    )
    assert "; did you mean 'walk_s'? (applied to " in bad.stderr and "open_field.toml)" in bad.stderr
    low = vplane_mj("run", "open_field", "--planner", EXAMPLE_SPEC, "--set", "planner.walk_s=0", cwd=tmp_path)
    assert low.returncode == 2 and "--set planner.walk_s: must be greater than 0, got 0" in low.stderr
    listed = vplane_mj("list", "--planner", EXAMPLE_SPEC, "--planner", "apf", cwd=tmp_path)
    assert listed.returncode == 0, listed.stderr
    lines = listed.stdout.splitlines()
    assert "  random_walk: APF with a random-walk escape from local minima (an example planner)" in lines
    assert any(line.split()[:3] == ["walk_s", "10", "s"] for line in lines)
    assert any(line.startswith("  apf: ") for line in lines) and "Built-in scenarios:" not in lines


# -- registration in code, and in the workers of a sweep ----------------------------------------


@dataclass(frozen=True)
class StraightParams(DetectorParams):
    speed: float = param(0.6, "", "force toward the goal", gt=0, le=2)


class StraightPlanner(Planner):
    """Straight to the goal, blind."""

    name = "straight"
    summary = "straight to the goal"
    citation = ""
    Params = StraightParams

    def step(self, obs: Observation):
        from vplane_mj.planning import Decision, unit

        return Decision(force=self.params.speed * unit(obs.goal - obs.position), mode="normal")


def test_register_planner_makes_a_class_nameable_by_scenarios(own_registry, shipped):
    assert "straight" not in own_registry
    with pytest.raises(ScenarioError, match="unknown planner 'straight'"):
        shipped("open_field", "planner.name=straight")
    assert register_planner(StraightPlanner) is StraightPlanner
    assert register_planner(StraightPlanner) is StraightPlanner  # again: nothing changes
    assert list(own_registry)[-1] == "straight"
    summary = run_scenario(shipped("open_field", "planner.name=straight", "planner.speed=1.2")).summary
    assert summary.planner == "straight" and summary.reached
    assert summary.planner_params == {**StraightParams().as_dict(), "speed": 1.2}
    with pytest.raises(ScenarioError) as error:
        shipped("open_field", "planner.name=straight", "planner.speed=3")
    assert (error.value.key, error.value.reason) == ("planner.speed", "must be at most 2, got 3")


def test_register_planner_refuses_what_is_no_planner(own_registry):
    class Undecorated(StraightParams):  # no @dataclass(frozen=True): `gain` would be no field
        gain: float = param(1.0, "", "a gain")

    @dataclass(frozen=True)
    class Plain(PlannerParams):
        gain: float = 1.0  # not made by param()

    @dataclass(frozen=True)
    class OutOfBounds(PlannerParams):
        gain: float = param(-1.0, "", "a gain", ge=0)

    cases = {
        "its Params must be a frozen dataclass: put @dataclass(frozen=True) above its class": {
            "Params": Undecorated
        },
        "its Params must be a subclass of vplane_mj.planning.PlannerParams, not dict": {"Params": dict},
        "its parameter 'gain' is not made by param(...)": {"Params": Plain},
        "the default of its parameter 'gain' must be at least 0, got -1.0": {"Params": OutOfBounds},
        "its name must match [a-z0-9_]+": {"name": "Straight"},
        "its name 'vplane' is a built-in planner's": {"name": "vplane"},
    }
    for reason, attributes in cases.items():
        cls = type("Variant", (StraightPlanner,), attributes)
        with pytest.raises(PlannerError, match=re.escape(reason)):
            register_planner(cls)
    register_planner(StraightPlanner)
    with pytest.raises(PlannerError, match="the name 'straight' is taken by"):
        register_planner(type("Other", (StraightPlanner,), {}))
    with pytest.raises(PlannerError, match="does not implement step"):
        register_planner(type("Abstract", (Planner,), {"name": "abstract", "summary": "", "citation": ""}))


def test_a_fresh_worker_registers_the_classes_the_job_names(own_registry):
    load_planner(EXAMPLE_SPEC)
    jobs = plan_jobs(["open_field"], ["random_walk", "apf"], [3], ["run.time_limit_s=2"])
    assert jobs[0].key.startswith("open_field|random_walk|3|")  # the key of a built-in's job, same form
    assert jobs[0].registered_planner == canonical_spec(EXAMPLE_SPEC)  # what a worker must import
    assert jobs[1].registered_planner is None  # a built-in planner: nothing
    # A spawned process starts with nothing registered, as a Dask worker does.
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        row = pool.submit(run_job, jobs[0]).result(timeout=300)
    assert row["key"] == jobs[0].key and row["planner"] == "random_walk" and row["outcome"] == "timeout"


def test_the_example_walks_out_of_a_trap_repeatably(own_registry):
    cls = load_planner(EXAMPLE_SPEC)
    assert load_planner(EXAMPLE_SPEC) is cls and own_registry["random_walk"] is cls

    def decisions(seed: int) -> list:
        planner = cls.build({"walk_seed": seed}, robot_radius_m())
        bearings = np.linspace(0.0, 2 * np.pi, 8, endpoint=False)
        ranges = np.array([0.3] + [np.nan] * 7)  # a wall right in front of the robot
        goal, here = np.array([5.0, 1.0]), np.array([1.0, 1.0])
        # 12 s at 20 Hz without moving: a local minimum after 6 s, then a random walk
        return [
            planner.step(Observation(tick * 0.05, here, 0.0, goal, 0.15, bearings, ranges, 0.35))
            for tick in range(240)
        ]

    first, again, other = decisions(0), decisions(0), decisions(1)
    modes = [d.mode for d in first]
    assert modes[0] == "normal" and modes[-1] == "escaping" and sum(d.local_minimum for d in first) == 1
    walking = [d for d in first if d.mode == "escaping"]
    assert all(np.isclose(np.hypot(*d.components["attractive"]), 0.8) for d in walking)
    assert len({tuple(d.components["attractive"]) for d in walking}) >= 2  # a new direction every 2 s
    assert all(np.array_equal(a.force, b.force) for a, b in zip(first, again, strict=True))
    assert not all(np.array_equal(a.force, b.force) for a, b in zip(first, other, strict=True))


# -- installed entry points -------------------------------------------------------------------

INSTALLED = """
from vplane_mj.planning import Decision, DetectorParams, Planner, param
from dataclasses import dataclass
import sys
print("IMPORTING wander_pkg", file=sys.stderr)

@dataclass(frozen=True)
class WanderParams(DetectorParams):
    pull: float = param(0.7, "", "force toward the goal", gt=0)

class Wander(Planner):
    name = "wander"
    summary = "an installed planner"
    citation = "none"
    Params = WanderParams

    def step(self, obs):
        return Decision(force=self.params.pull * (obs.goal - obs.position), mode="normal")
"""


@pytest.mark.slow
def test_an_installed_entry_point_is_listed_without_import_and_usable_by_name(tmp_path):
    site = tmp_path / "site"
    (site / "wander_pkg").mkdir(parents=True)
    (site / "wander_pkg" / "__init__.py").write_text(INSTALLED)
    info = site / "wander_pkg-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: wander-pkg\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[vplane_mj.planners]\nwander = wander_pkg:Wander\n")
    env = {**os.environ, "PYTHONPATH": str(site)}
    probe = textwrap.dedent(
        """
        import sys
        from vplane_mj.planning.protocol.registry import PLANNERS
        names = list(PLANNERS)
        print(names[-1], "wander" in PLANNERS, "wander_pkg" in sys.modules)
        print(PLANNERS["wander"].Params().pull, "wander_pkg" in sys.modules)
        """
    )
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=env, timeout=120)
    assert done.stdout.split("\n")[:2] == ["wander True False", "0.7 True"], done.stdout + done.stderr
    (tmp_path / "uses_it.toml").write_text(OPEN_FIELD.format(planner="wander"))
    run = vplane_mj("run", "uses_it.toml", "--no-render", "--no-log", "--out", "out", cwd=tmp_path, env=env)
    assert run.returncode == 0, run.stderr
    assert json.loads((tmp_path / "out" / "from_a_file-wander-0.json").read_text())["planner"] == "wander"
    listed = vplane_mj("list", cwd=tmp_path, env=env)
    assert "  wander: an installed planner" in listed.stdout.splitlines()


def test_sweep_takes_planner_classes_and_import_specs(own_registry):
    cls = load_planner(EXAMPLE_SPEC)
    result = sweep(["open_field"], [cls, "apf"], [0], ["run.time_limit_s=3"], jobs=1, out=None)
    assert [row["planner"] for row in result.rows] == ["random_walk", "apf"]
    assert all(row["outcome"] == "timeout" for row in result.rows)  # 3 s is too short to arrive
    with pytest.raises(VPlaneError, match=r"^planners: nowhere:Nope: cannot import nowhere"):
        sweep(["open_field"], ["nowhere:Nope"], [0], jobs=1, out=None)


# -- planners defined in the calling script -----------------------------------------------------

SCRIPT_PLANNERS = """
import json
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path

import vplane_mj
from vplane_mj.planning import Decision, Planner, PlannerParams, param, register_planner

# a line each time this file runs, beside it whatever the directory it runs in
with open(Path(__file__).with_name("executions.txt"), "a") as executions:
    executions.write("ran\\n")


@dataclass(frozen=True)
class StraightParams(PlannerParams):
    gain: float = param(0.5, "", "force per metre to the goal", gt=0)


class Straight2(Planner):
    name = "straight2"
    summary = "straight to the goal"
    citation = "none"
    Params = StraightParams

    def step(self, obs):
        return Decision(force=self.params.gain * (obs.goal - obs.position), mode="normal")


class Boom2(Straight2):
    name = "boom2"
    summary = "straight to the goal, and a bug after a second"

    def step(self, obs):
        if obs.time_s >= 1.0:
            raise ZeroDivisionError("boom")
        return super().step(obs)
"""

UNGUARDED_SWEEP = """
scheduler = sys.argv[1] if len(sys.argv) > 1 else None
register_planner(Straight2)
planners = ["apf", Straight2 if scheduler else "straight2"]  # by class, or registered and by name
result = vplane_mj.sweep(["open_field", "single_box"], planners, seeds=[0, 1], jobs=2,
                         scheduler=scheduler, out=None, overrides=["run.time_limit_s=25"])
print(json.dumps([[row["scenario"], row["planner"], row["seed"], row["outcome"]] for row in result.rows]))
"""


def run_script(path: Path, *args: str) -> subprocess.CompletedProcess:
    """`python SCRIPT ARGS` in the script's directory, as a user runs their script."""
    return subprocess.run(
        [sys.executable, path.name, *args], cwd=path.parent, capture_output=True, text=True, timeout=600
    )


@pytest.mark.slow
@pytest.mark.parametrize("engine", ["local", "dask"])
def test_a_planner_class_of_the_calling_script_runs_in_the_workers(tmp_path, engine):
    script = tmp_path / "my_sweep.py"
    script.write_text(SCRIPT_PLANNERS + UNGUARDED_SWEEP)  # no `if __name__ == "__main__":`
    if engine == "local":
        done = run_script(script)
    else:
        distributed = pytest.importorskip("distributed")
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster:
            done = run_script(script, cluster.scheduler_address)
    assert done.returncode == 0, done.stderr
    rows = json.loads(done.stdout.splitlines()[-1])
    assert [row[:3] for row in rows] == [
        [scenario, planner, seed]
        for scenario in ("open_field", "single_box")
        for planner in ("apf", "straight2")
        for seed in (0, 1)
    ]
    assert all(outcome != "error" for *_, outcome in rows), rows
    assert [outcome for scenario, planner, _, outcome in rows if scenario == "open_field"] == ["reached"] * 4
    # The workers got the class without running the script again (its sweep included).
    assert (tmp_path / "executions.txt").read_text() == "ran\n"
    assert "SweepErrorWarning" not in done.stderr


GUARDED_SWEEP_WITH_ERRORS = """
if __name__ == "__main__":
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = vplane_mj.sweep(["open_field"], ["apf", Straight2, Boom2], seeds=[0, 1], jobs=2,
                                 out="out", report=False, overrides=["run.time_limit_s=25"])
    said = [(warning.category.__name__, str(warning.message)) for warning in caught]
    print(json.dumps({"warnings": said, "errors": result.errors}))
"""


@pytest.mark.slow
def test_a_sweep_whose_planner_raises_warns_and_each_error_runs_again_by_its_command(tmp_path):
    script = tmp_path / "my_sweep.py"
    script.write_text(SCRIPT_PLANNERS + GUARDED_SWEEP_WITH_ERRORS)
    done = run_script(script)
    assert done.returncode == 0, done.stderr
    said = json.loads(done.stdout.splitlines()[-1])
    [(category, warning)] = said["warnings"]
    raised = f"planner 'boom2' raised at t = 1.000 s: ZeroDivisionError: boom (at {script}:"
    assert category == "SweepErrorWarning"
    first = "the first, open_field with boom2 and seed 0"
    assert warning.startswith(f"2 of 6 runs ended in error (SweepResult.errors); {first}: {raised}")
    assert [(row["planner"], row["seed"]) for row in said["errors"]] == [("boom2", 0), ("boom2", 1)]
    error = said["errors"][0]
    assert error["message"].startswith(raised) and error["message"].endswith(" in step)")
    assert error["traceback"].rstrip().endswith("ZeroDivisionError: boom")
    saved = Path("out") / "failed" / "open_field-boom2-0.toml"
    assert error["failed_scenario"] == str(saved)
    assert error["rerun"] == f"vplane-mj run {saved} --planner {script}:Boom2"
    assert (tmp_path / saved).read_text().splitlines()[:2] == [
        "# A run of a sweep that ended in error; to run it again:",
        f"# {error['rerun']}",
    ]
    assert "ZeroDivisionError: boom" in (tmp_path / saved.with_suffix(".traceback.txt")).read_text()
    # The command runs it again: the same run, the same error (exit 3), not an unknown planner.
    again = vplane_mj(*shlex.split(error["rerun"])[1:], "--out", "again", "--no-render", cwd=tmp_path)
    assert again.returncode == 3, again.stderr
    rerun = json.loads((tmp_path / "again" / "open_field-boom2-0.json").read_text())
    assert rerun["message"] == error["message"] and rerun["sim_time_s"] == error["sim_time_s"]
    assert (tmp_path / "executions.txt").read_text() == "ran\n" * 2  # the script, then its import


@pytest.mark.slow
def test_the_documented_planner_snippets_run_as_a_script(tmp_path, doc_examples):
    """The code of docs/own-planner.md, as a user's script: the planner class, registered in
    code, run by `vplane_mj.run` and swept by `vplane_mj.sweep` with a planner file."""
    script = tmp_path / "own_planner.py"
    script.write_text(doc_examples("own-planner.md", "Parameters and class attributes", "Registering it"))
    done = subprocess.run(
        [sys.executable, str(script)], cwd=ROOT, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == "reached 0.6"
    header, *table = lines[1:]
    assert header.split()[:4] == ["planner", "governor", "runs", "success_rate"]
    rows = [row.split() for row in table if row.split() and row.split()[0].isidentifier()]  # no rules
    assert [(row[0], row[1], row[2]) for row in rows] == [
        ("apf", "own", "4"),
        ("cautious", "run", "4"),
        ("random_walk", "run", "4"),
    ]
    assert "SweepErrorWarning" not in done.stderr
