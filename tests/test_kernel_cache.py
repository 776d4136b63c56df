"""The compiled kernels' cache: never stale, wherever the edit is."""

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
