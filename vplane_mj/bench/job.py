"""One run of a sweep, as the journal keys it and a worker receives it."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

from vplane_mj.planning.protocol.registry import WorkerPlanner


@dataclass(frozen=True)
class Job:
    """One run of a sweep: the resolved scenario text and where it came from.

    `registered_planner` is the job's planner when it was registered in the calling process,
    as the worker registers it before it reads the scenario (`registry.for_worker`: an import
    spec such as `module:Class` or `/abs/path/file.py:Class`, or a class of the calling
    script); None for a built-in or installed one. `files` is the folder into which the run
    writes its log and its ROS 2 bag (`bench --ros2`), None for none. Neither is part of the
    key: a run is the same run whichever way its planner was found and whatever it writes.
    """

    scenario: str
    planner: str
    seed: int
    toml: str
    registered_planner: WorkerPlanner | None = None
    files: str | None = None

    @property
    def key(self) -> str:
        """Identifies a run across invocations: scenario content, planner and seed."""
        digest = hashlib.sha256(self.toml.encode()).hexdigest()[:16]
        return f"{self.scenario}|{self.planner}|{self.seed}|{digest}"
