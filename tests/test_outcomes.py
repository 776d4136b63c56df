"""Every way a run ends, on a real run: the stored summary says it, and `vplane-mj summary LOG`
recomputes the same outcome and message from the log's events alone."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from vplane_mj.cli import main
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.types import Decision
from vplane_mj.sim import loop as sim
from vplane_mj.sim.world import build_model

ALL_SONARS_DEAD = "sensors.dead=[" + ",".join(str(i) for i in range(16)) + "]"


class _NaNAfterOneSecond(Planner):
    """A planner that drives toward the goal, then returns a non-finite force after 1 s."""

    name = "nan_after_one_second"
    summary = "a non-finite force after 1 s"
    citation = ""

    def step(self, obs):
        direction = (obs.goal - obs.position) / max(obs.distance_to_goal(), 1e-9)
        return Decision(force=direction if obs.time_s < 1.0 else np.array([math.nan, 0.0]), mode="normal")


def _unstable_model(scenario, **options):
    """The scenario's model with negative joint damping: MuJoCo's state blows up within a step."""
    model = build_model(scenario, **options)
    model.dof_damping[:] = -1e6
    return model


CASES = {
    # name: (scenario, overrides, outcome, start of the message)
    "reached": ("paper_c_escape", [], "reached", ""),
    "timeout": ("open_field", ["run.time_limit_s=1"], "timeout", ""),
    "stuck_planner_gave_up": ("paper_c_escape", ["planner.name=apf"], "stuck", "gave up: trapped for"),
    "stuck_nothing_mapped": (
        "paper_c_escape",
        [ALL_SONARS_DEAD],
        "stuck",
        "local minimum without mapped obstacles: no escape possible",
    ),
    "stuck_odometry": (
        "open_field",
        ['sensors.pose="odometry"', "sensors.odometry_noise=0.3"],
        "stuck",
        "odometry has put the robot at the goal",
    ),
    "stuck_ekf": (
        "open_field",
        ['sensors.pose="ekf"', "sensors.odometry_noise=0.9"],
        "stuck",
        "the EKF has put the robot at the goal",
    ),
    "error_mujoco_warning": ("open_field", [], "error", "MuJoCo warning at t = "),
    "error_non_finite_force": ("open_field", [], "error", "planner 'vplane' gave a non-finite force"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_log_reproduces_how_the_run_ended(case, tmp_path, capsys, monkeypatch):
    name, overrides, outcome, message = CASES[case]
    monkeypatch.chdir(tmp_path)  # MuJoCo writes its warnings to MUJOCO_LOG.TXT in the working directory
    if case == "error_mujoco_warning":
        monkeypatch.setattr(sim, "build_model", _unstable_model)
    if case == "error_non_finite_force":
        monkeypatch.setattr(
            sim, "make_planner", lambda _name, _params, body: _NaNAfterOneSecond.build({}, body)
        )
    settings = [item for override in overrides for item in ("--set", override)]
    code = main(["run", name, *settings, "--out", str(tmp_path / "out"), "--no-render"])
    capsys.readouterr()
    assert code == (0 if outcome == "reached" else 1)
    (stored_path,) = (tmp_path / "out").glob("*.json")
    stored = json.loads(stored_path.read_text())
    assert stored["outcome"] == outcome and stored["message"].startswith(message), stored["message"]

    assert main(["summary", str(stored_path.with_suffix(".mcap"))]) == 0
    out = capsys.readouterr().out
    assert out.rstrip().endswith("agrees with the run's stored summary")
    recomputed = json.loads(out[: out.index("\nevents:")])
    assert (recomputed["outcome"], recomputed["message"]) == (stored["outcome"], stored["message"])
    assert recomputed["sim_time_s"] == pytest.approx(stored["sim_time_s"], abs=1e-6)
