"""An example planner from outside the package: APF with a random-walk escape (`random_walk`).

F = F_A + F_R (Khatib's fields) until the local-minimum detector fires; then the robot walks
for `walk_s` seconds in random directions, a new one every `turn_every_s`, still repelled by
the echoes, and APF takes over again. After `max_walks` walks it gives up (outcome `stuck`).
The walk is random but repeatable: its generator is seeded with `walk_seed` and the start
position (mm), so the same scenario and parameters give the same run.

    vplane-mj run paper_c_escape --planner examples/random_walk_planner.py:RandomWalkPlanner
    vplane-mj bench paper_c_escape --planners apf,examples/random_walk_planner.py:RandomWalkPlanner
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning import (
    Decision,
    DetectorParams,
    Event,
    EventKind,
    FieldParams,
    Observation,
    Planner,
    param,
)


@dataclass(frozen=True)
class RandomWalkParams(DetectorParams, FieldParams):
    """APF's fields and the local-minimum detector, then the walk's own parameters."""

    walk_s: float = param(10.0, "s", "how long one random walk lasts", gt=0)
    turn_every_s: float = param(2.0, "s", "a new random direction this often during a walk", gt=0)
    walk_force: float = param(0.8, "", "force magnitude of the walk (0.5 m/s per unit)", gt=0)
    max_walks: int = param(8, "", "random walks tried before giving up", ge=1, integer=True)
    walk_seed: int = param(
        0, "", "seed of the walk's directions (with the start position)", ge=0, integer=True
    )


class RandomWalkPlanner(Planner):
    """APF, and a random walk out of each local minimum."""

    name = "random_walk"
    summary = "APF with a random-walk escape from local minima (an example planner)"
    citation = (
        "J. Barraquand, J.-C. Latombe, Robot motion planning: a distributed representation "
        "approach, IJRR 10(6), 1991 (random walks out of potential-field minima)"
    )
    Params = RandomWalkParams
    params: RandomWalkParams

    def __init__(self, params: RandomWalkParams, robot_radius_m: float):
        super().__init__(params, robot_radius_m)
        self.detector = params.detector()
        self.rng: np.random.Generator | None = None
        self.walk_ends_s: float | None = None
        self.next_turn_s = 0.0
        self.direction = np.zeros(2)
        self.walks = 0

    def step(self, obs: Observation) -> Decision:
        p = self.params
        if self.rng is None:  # seeded once, from the parameters and where the run starts
            start_mm = [round(1000 * float(v)) % 2**32 for v in obs.position]
            self.rng = np.random.default_rng([p.walk_seed, *start_mm])
        components = p.firas_components(obs)
        decision = Decision(force=np.zeros(2), mode="normal", components=components)
        near_goal = obs.distance_to_goal() <= obs.goal_tolerance
        if self.detector.update(obs.time_s, obs.position, near_goal).new and self.walk_ends_s is None:
            decision.local_minimum = True
            decision.events.append(Event(EventKind.LOCAL_MINIMUM, "local minimum detected"))
            if self.walks >= p.max_walks:
                decision.gave_up = True
                decision.events.append(Event(EventKind.GAVE_UP, f"gave up after {self.walks} random walks"))
                return decision
            self.walks += 1
            self.walk_ends_s, self.next_turn_s = obs.time_s + p.walk_s, obs.time_s
            decision.events.append(Event(EventKind.ESCAPE_STARTED, f"random walk {self.walks} started"))
        if self.walk_ends_s is not None and obs.time_s >= self.walk_ends_s:
            self.walk_ends_s = None
            self.detector.reset()
            decision.escape_completed = True
            decision.events.append(Event(EventKind.ESCAPE_FINISHED, f"random walk {self.walks} finished"))
        if self.walk_ends_s is not None:
            if obs.time_s >= self.next_turn_s:
                angle = self.rng.uniform(-math.pi, math.pi)
                self.direction = np.array([math.cos(angle), math.sin(angle)])
                self.next_turn_s = obs.time_s + p.turn_every_s
            decision.mode = "escaping"
            components["attractive"] = p.walk_force * self.direction
        decision.force = components["attractive"] + components["repulsive"]
        return decision
