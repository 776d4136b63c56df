"""An example planner from outside the package: straight to the goal, pushed off by the scan
(`go_to_goal`).

F = the unit vector toward the goal + the sum, over the echoes nearer than `reach_m`, of
`push` (1/d - 1/reach) / d^2 away from each (d in m; Khatib's repulsion without its gain
schedule). It has no escape and no care for the robot's shape: the run's governor drives its
force on the robot's body (on by default; `--set planner.governor=false` turns it off).

    vplane-mj run barn/barn_world_1.toml --planner examples/go_to_goal_planner.py:GoToGoalPlanner
    vplane-mj bench paper_c_escape --planners apf,examples/go_to_goal_planner.py:GoToGoalPlanner
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vplane_mj.planning import Decision, Observation, Planner, PlannerParams, param


@dataclass(frozen=True)
class GoToGoalParams(PlannerParams):
    """How far the echoes push, and how hard."""

    reach_m: float = param(0.8, "m", "echoes nearer than this push the robot away", gt=0)
    push: float = param(0.01, "", "gain of the push (force m^3: at d = reach / 2, push / d^2)", ge=0)


class GoToGoalPlanner(Planner):
    """Straight to the goal, pushed off by the echoes."""

    name = "go_to_goal"
    summary = "straight to the goal, pushed off by the scan (an example planner)"
    citation = "O. Khatib, IJRR 5(1), 1986 (the repulsion)"
    Params = GoToGoalParams
    params: GoToGoalParams

    def step(self, obs: Observation) -> Decision:
        toward = (obs.goal - obs.position) / max(obs.distance_to_goal(), 1e-9)
        away = obs.position - obs.echo_points()
        d = np.hypot(away[:, 0], away[:, 1])
        near = d < self.params.reach_m
        gain = self.params.push * (1 / d[near] - 1 / self.params.reach_m) / d[near] ** 3
        push = (away[near] * gain[:, None]).sum(axis=0)
        return Decision(
            force=toward + push,
            mode="normal",
            components={"attractive": toward, "repulsive": push},
        )
