"""The compiled kernels' cache: never stale, wherever the edit is."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import vplane_mj

PACKAGE = Path(vplane_mj.__file__).parent

CALL = """
import numpy as np
from vplane_mj.kernels import CACHE_PATH
from vplane_mj.kernels.motion import way
# A cell 0.5 m from the way's one point, against a gap of 0.6 m: way.blocked asks outline.closer.
print(way.blocked(0.0, 0.0, np.zeros((1, 2)), 1.0, np.array([[0.5, 0.0]]), 0.6), CACHE_PATH)
"""


def blocked_in(copy: Path) -> tuple[str, str]:
    """What the copy's `way.blocked` answers, in a new process, and where its cache lies."""
    done = subprocess.run(
        [sys.executable, "-c", CALL],
        cwd=copy,
        capture_output=True,
        text=True,
        timeout=600,
        env={"PATH": "/usr/bin:/bin", "PYTHONPATH": str(copy), "HOME": str(copy)},
    )
    assert done.returncode == 0, done.stderr[-2000:]
    answer, cache = done.stdout.split()
    return answer, cache


def test_a_kernel_whose_callee_in_another_module_changed_is_compiled_again(tmp_path):
    shutil.copytree(PACKAGE, tmp_path / "vplane_mj", ignore=shutil.ignore_patterns("__pycache__"))
    before, first_cache = blocked_in(tmp_path)
    assert before == "True" and blocked_in(tmp_path) == (before, first_cache)  # the second run loads it
    callee = tmp_path / "vplane_mj" / "kernels" / "motion" / "outline.py"
    text = callee.read_text()
    assert "SURE_M = 1e-9\n" in text and "    return math.hypot(dx, dy) < bound\n" in text
    edited = text.replace("SURE_M = 1e-9\n", "SURE_M = 1.0\n").replace(
        "    return math.hypot(dx, dy) < bound\n", "    return math.hypot(dx, dy) < 0.5 * bound\n"
    )
    callee.write_text(edited)
    after, second_cache = blocked_in(tmp_path)
    assert after == "False" and second_cache != first_cache


LOOP = """
import json
from vplane_mj import kernels
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import Run, kernel_kind

def loaded():
    return sum(len(dispatcher.overloads) for dispatcher in kernels.DISPATCHERS.values())

run = Run(load_scenario("paper_c_escape", ["planner.name=apf", "run.time_limit_s=8"]))
before = loaded()
load_s = kernels.preload(kernel_kind("apf", "sonar"))
ready = loaded()
while run.step() is None:
    pass
print(json.dumps({"before": before, "ready": ready, "after": loaded(), "load_s": load_s}))
"""


def test_a_run_loads_the_kernels_its_kind_used_before_its_loop(tmp_path):
    first = run(
        [
            "run",
            "paper_c_escape",
            "--planner",
            "apf",
            "--set",
            "run.time_limit_s=8",
            "--no-log",
            "--no-render",
            "--out",
            str(tmp_path),
        ]
    )
    assert first.returncode == 1  # apf stays trapped: the run times out, and its kernels are remembered
    summary = json.loads((tmp_path / "paper_c_escape-apf-0.json").read_text())
    assert summary["kernel_load_s"] >= 0.0 and summary["wall_time_s"] > 0.0
    done = subprocess.run([sys.executable, "-c", LOOP], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    counts = json.loads(done.stdout)
    assert counts["ready"] > counts["before"] and counts["load_s"] > 0.0
    assert counts["after"] == counts["ready"]  # nothing loaded or compiled inside the loop


def run(argv: list[str]) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "vplane_mj", *argv], capture_output=True, text=True, timeout=600
    )
