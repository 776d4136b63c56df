"""vplane-mj: artificial potential fields and the virtual-plane escape from local minima in MuJoCo.

The Python API (docs/python-api.md): `load_scenario` and `build_scenario` (with the obstacle
helpers `box`, `wall`, `cylinder`, `cup`, `h_shape`), `run` and `sweep`. Each name is imported
on first use, so `import vplane_mj` loads neither MuJoCo nor any plotting or OpenGL library.

The package's layers, top down (each imports only from those below it; `pyproject.toml` holds
them as an import-linter contract): `cli`; `runner` and `sweeps` (the run and the sweep as the
API gives them); `envs` and `bench`; `viz`; `logs`; `sim` and `worlds`; `scenario`; `robots`;
`planning` and `geometry`; `files` and `terminal`; `errors` and `version`.
"""

import importlib
import os
from typing import TYPE_CHECKING, Any

from vplane_mj.version import CONTRACT_VERSION as CONTRACT_VERSION
from vplane_mj.version import __version__ as __version__

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
    "vplane_mj.planning.protocol.events": ("EventKind",),
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
    from vplane_mj.planning.protocol.events import EventKind
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


def __getattr__(name: str) -> Any:
    """A public name, imported from its module on first use (PEP 562)."""
    module = _MODULE_OF.get(name)
    if module is None:
        raise AttributeError(f"module 'vplane_mj' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
