"""Planning: numpy, with its inner loops compiled (`kernels`, numba), no MuJoCo. What a
planner receives each control tick and what it answers.

The names for writing a planner of one's own (docs/own-planner.md):

- `Planner`: the base class (name, summary, citation, Params; `step(obs) -> Decision`);
- `RobotBody`, `DriveLimits`, `HeadingGains`: the robot a planner is built for (footprint,
  limits, the heading controller's gains, sensor kind);
- `Observation`, `Decision`, `Event`, `EventKind`, `point`: what it receives and returns;
  `Track`, an obstacle the run's tracker follows (`Observation.tracks`);
- `PlannerParams`, `param`, `with_default`: its parameters as a frozen dataclass;
- `FieldParams`, `DetectorParams`, `MinimumParams`, `LocalMapParams`, `SonarMapParams`,
  `MotionParams`: the parameter groups of the built-in planners with their set-ups (fields,
  local-minimum detector, sonar map and histogram, the governor's margins), `report_trap`,
  `LocalMinimumDetector`, `LocalMap`;
- `RunGovernor`: the governor a run drives a planner's forces through when the planner does
  not drive its body itself;
- `wrap_angle`, `unit`: angles and vectors;
- `register_planner`, `load_planner`: registration in code.
"""

from vplane_mj.planning.perception.localmap import LocalMap
from vplane_mj.planning.perception.minima import LocalMinimumDetector, report_trap
from vplane_mj.planning.perception.tracker import Track
from vplane_mj.planning.planners.groups import (
    DetectorParams,
    FieldParams,
    LocalMapParams,
    MinimumParams,
    MotionParams,
    SonarMapParams,
)
from vplane_mj.planning.planners.run_governor import RunGovernor
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.body import DriveLimits, HeadingGains, RobotBody
from vplane_mj.planning.protocol.events import Event, EventKind, point
from vplane_mj.planning.protocol.params import Param, ParamError, PlannerParams, param, with_default
from vplane_mj.planning.protocol.plugins import PlannerError
from vplane_mj.planning.protocol.registry import load_planner, register_planner
from vplane_mj.planning.protocol.types import Decision, Observation
from vplane_mj.planning.protocol.vectors import unit, wrap_angle

__all__ = [
    "Decision",
    "DetectorParams",
    "DriveLimits",
    "Event",
    "EventKind",
    "FieldParams",
    "HeadingGains",
    "LocalMap",
    "LocalMapParams",
    "LocalMinimumDetector",
    "MinimumParams",
    "MotionParams",
    "Observation",
    "Param",
    "ParamError",
    "Planner",
    "PlannerError",
    "PlannerParams",
    "RobotBody",
    "RunGovernor",
    "SonarMapParams",
    "Track",
    "load_planner",
    "param",
    "point",
    "register_planner",
    "report_trap",
    "unit",
    "with_default",
    "wrap_angle",
]
