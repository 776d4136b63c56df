"""vplane-mj: artificial potential fields and the virtual-plane escape from local minima in MuJoCo.

The Python API (docs/python-api.md): `load_scenario` and `build_scenario` (with the obstacle
helpers `box`, `wall`, `cylinder`, `cup`, `h_shape`), `run` and `sweep`. Each name is imported
on first use, so `import vplane_mj` loads neither MuJoCo nor any plotting or OpenGL library.

The package's layers, top down (each imports only from those below it; `pyproject.toml` holds
them as an import-linter contract): `cli`; `runner` and `sweeps` (the run and the sweep as the
API gives them); `envs` and `bench`; `viz`; `logs`; `sim` and `worlds`; `scenario`; `robots`;
`planning` and `geometry`; `files` and `terminal`; `errors`. Modules that stood at the top
before 0.2 keep their old import paths (`vplane_mj.gym_env`, say) as aliases of their new ones.
"""

import importlib
import os
import sys
import types
import warnings
from typing import TYPE_CHECKING, Any

__version__ = "0.2.0"
CONTRACT_VERSION = "1.3"
"""The version of the public contract (docs/interface.md: scenario format, command line,
outputs, log topics) this package follows."""

# The tool runs headless: render offscreen with OSMesa unless the user chose a backend.
# Set before mujoco imports OpenGL, which would otherwise try GLFW and X11.
GL_CHOSEN_BY_USER = "MUJOCO_GL" in os.environ
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])

_EXPORTS = {
    "vplane_mj.scenario": (
        "Scenario",
        "ScenarioError",
        "box",
        "build_scenario",
        "cup",
        "cylinder",
        "h_shape",
        "load_scenario",
        "wall",
    ),
    "vplane_mj.errors": ("VPlaneError",),
    "vplane_mj.files": ("OutputBusy",),
    "vplane_mj.sim.summary": ("Outcome", "RunSummary"),
    "vplane_mj.planning.events": ("EventKind",),
    "vplane_mj.runner": ("RunEvent", "RunRecord", "Trajectory", "run"),
    "vplane_mj.sweeps": ("SweepErrorWarning", "SweepResult", "sweep"),
}
"""Module -> the public names it provides."""
_MODULE_OF = {name: module for module, names in _EXPORTS.items() for name in names}

__all__ = [
    "EventKind",
    "Outcome",
    "OutputBusy",
    "RunEvent",
    "RunRecord",
    "RunSummary",
    "Scenario",
    "ScenarioError",
    "SweepErrorWarning",
    "SweepResult",
    "Trajectory",
    "VPlaneError",
    "box",
    "build_scenario",
    "cup",
    "cylinder",
    "h_shape",
    "load_scenario",
    "run",
    "sweep",
    "wall",
]

if TYPE_CHECKING:
    from vplane_mj.errors import VPlaneError
    from vplane_mj.files import OutputBusy
    from vplane_mj.planning.events import EventKind
    from vplane_mj.runner import RunEvent, RunRecord, Trajectory, run
    from vplane_mj.scenario import (
        Scenario,
        ScenarioError,
        box,
        build_scenario,
        cup,
        cylinder,
        h_shape,
        load_scenario,
        wall,
    )
    from vplane_mj.sim.summary import Outcome, RunSummary
    from vplane_mj.sweeps import SweepErrorWarning, SweepResult, sweep


MOVED_MODULES = {
    "barn_import": "worlds.barn_import",
    "barn_layout": "worlds.barn_layout",
    "barn_protocol": "worlds.barn_protocol",
    "bench_report": "bench.report",
    "cache": "geometry.cache",
    "control": "sim.control",
    "dm_environment": "envs.dm_environment",
    "drive": "sim.drive",
    "failures": "bench.failures",
    "families": "worlds.families",
    "gym_env": "envs.gym_env",
    "interrupts": "terminal",
    "laser": "sim.laser",
    "log_mcap": "logs.writer",
    "log_read": "logs.reader",
    "log_scene": "logs.scene",
    "metrics": "sim.metrics",
    "mjcf_reader": "robots.mjcf_reader",
    "navigation_task": "envs.task",
    "odometry": "sim.odometry",
    "outputs": "files",
    "plots": "viz.plots",
    "polyline": "geometry.polyline",
    "pool": "bench.pool",
    "profiles": "robots.profiles",
    "reference": "geometry.reference",
    "render": "viz.render",
    "replay": "logs.replay",
    "resources": "files",
    "robot": "robots.facts",
    "sdf_world": "worlds.sdf",
    "sensors": "sim.sensors",
    "shapes": "geometry.shapes",
    "sonar": "sim.sonar",
    "suggestions": "errors",
    "summary": "sim.summary",
    "synthetic": "geometry.synthetic",
    "timeline": "logs.timeline",
    "video": "viz.video",
    "world": "sim.world",
}
"""Old module (before 0.2) -> its new place under vplane_mj."""


class _MovedModule(types.ModuleType):
    """An old module path that stands for a new one: the new module is imported, with a
    DeprecationWarning, when an attribute is first looked up."""

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__") and name.endswith("__"):  # introspection imports nothing
            raise AttributeError(name)
        new = f"{__name__}.{MOVED_MODULES[self.__name__.rpartition('.')[2]]}"
        if not self.__dict__.get("_warned"):
            self.__dict__["_warned"] = True
            warnings.warn(f"{self.__name__} is now {new}", DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(new), name)


for _old in MOVED_MODULES:
    sys.modules.setdefault(f"{__name__}.{_old}", _MovedModule(f"{__name__}.{_old}"))


def __getattr__(name: str) -> Any:
    """A public name, imported from its module on first use (PEP 562)."""
    if name in MOVED_MODULES:
        return sys.modules[f"{__name__}.{name}"]
    module = _MODULE_OF.get(name)
    if module is None:
        raise AttributeError(f"module 'vplane_mj' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
