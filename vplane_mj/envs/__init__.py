"""Reinforcement-learning environments over the run loop: the navigation task they share
(`task`), Gymnasium's `VPlaneNavEnv` (`gym_env`) and dm_env's `VPlaneNavDmEnv` (`dm_environment`)
on dm_control's Physics (`physics`), and `PlannerPolicy` (`policy`), a planner as a dm_env
policy. Each is imported on first use (Gymnasium is an optional extra)."""

import importlib
from typing import Any

_EXPORTS = {
    "VPlaneNavEnv": "vplane_mj.envs.gym_env",
    "VPlaneNavDmEnv": "vplane_mj.envs.dm_environment",
    "PlannerPolicy": "vplane_mj.envs.policy",
}
__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    """An environment class, imported from its module on first use (PEP 562)."""
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'vplane_mj.envs' has no attribute {name!r}")
    return getattr(importlib.import_module(module), name)
