"""The files a run of a sweep writes with `bench --ros2`: its MCAP log and the ROS 2 bag made
from it, named as `vplane-mj run` names them (`<name>-<planner>-<seed>.mcap` and `.ros2`), each
written under a temporary name and renamed when whole."""

from __future__ import annotations

import os
from pathlib import Path

from vplane_mj.files import partial_path
from vplane_mj.logs.ros2 import export_ros2
from vplane_mj.logs.writer import McapLog
from vplane_mj.scenario import Scenario
from vplane_mj.sim.loop import RunResult, run_scenario
from vplane_mj.sim.sensors import scan_bearings


def run_with_bag(scenario: Scenario, folder: Path) -> RunResult:
    """Run `scenario`, logging it into `folder`, then write its bag there; the run's result."""
    base = folder / f"{scenario.name}-{scenario.planner}-{scenario.run.seed}"
    log = base.with_suffix(".mcap")
    temporary = partial_path(log)
    try:
        with McapLog(temporary, scenario, scan_bearings(scenario), {}) as mcap:
            result = run_scenario(scenario, (mcap,))
            mcap.close(result.summary.to_dict())
        os.replace(temporary, log)
    finally:
        temporary.unlink(missing_ok=True)
    export_ros2(log, base.with_suffix(".ros2"))
    return result
