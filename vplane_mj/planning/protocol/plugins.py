"""Planner classes from outside the package: checked, and imported only when the user asks.

A planner class is named by an import spec, `module:Class` (the module looked up as
`python -m` would, the current directory first) or `path/to/file.py:Class`. Only the command
line (`--planner`, `--planners`), code (`load_planner`, `register_planner`) and installed entry
points of the group `vplane_mj.planners` lead to an import; a scenario file names planners by
name only, so a file never makes anything be imported.
"""

from __future__ import annotations

import dataclasses
import importlib
import importlib.util
import inspect
import os
import re
import sys
from pathlib import Path
from types import ModuleType

from vplane_mj.errors import VPlaneError
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.params import PARAM, PlannerParams

NAME_PATTERN = re.compile(r"[a-z0-9_]+")
MAX_NAME_LENGTH = 64
"""A planner's name is part of output file names (`<scenario>-<planner>-<seed>.json`)."""
FILE_MODULE_PREFIX = "vplane_mj_planner_file_"
"""A planner file `path/x.py` is imported as the module `vplane_mj_planner_file_x`, so it never
takes the place of an installed module of the same name."""


class PlannerError(VPlaneError):
    """A planner class that cannot be imported, or is not a valid planner."""


def planner_problem(cls: object) -> str | None:
    """Why `cls` cannot be a planner, or None when it can: a concrete `Planner` subclass with a
    name of [a-z0-9_]+, a summary, a citation, and a frozen `PlannerParams` dataclass whose every
    field is made by `param` with a default within its bounds."""
    if not (inspect.isclass(cls) and issubclass(cls, Planner)):
        return "it is not a subclass of vplane_mj.planning.Planner"
    if inspect.isabstract(cls):
        return "it does not implement step(obs)"
    name = getattr(cls, "name", None)
    if not isinstance(name, str) or not NAME_PATTERN.fullmatch(name):
        return f"its name must match [a-z0-9_]+ (it names output files), got {name!r}"
    if len(name) > MAX_NAME_LENGTH:
        return f"its name must be at most {MAX_NAME_LENGTH} characters, got {len(name)}"
    for attribute in ("summary", "citation"):
        if not isinstance(getattr(cls, attribute, None), str):
            return f"it has no {attribute} (a string class attribute)"
    params = cls.Params
    if not (inspect.isclass(params) and issubclass(params, PlannerParams)):
        got = params.__name__ if inspect.isclass(params) else type(params).__name__
        return (
            f"its Params must be a subclass of vplane_mj.planning.PlannerParams, not {got} "
            "(a planner without parameters leaves Params out)"
        )
    own = vars(params)  # what @dataclass sets on the class itself, not inherited from a base
    if "__dataclass_fields__" not in own or not getattr(own.get("__dataclass_params__"), "frozen", False):
        return "its Params must be a frozen dataclass: put @dataclass(frozen=True) above its class"
    for field in dataclasses.fields(params):
        spec = field.metadata.get(PARAM)
        if spec is None:
            return f"its parameter {field.name!r} is not made by param(...)"
        reason = spec.check(spec.default)
        if reason:
            return f"the default of its parameter {field.name!r} {reason}"
    return None


def is_import_spec(text: str) -> bool:
    """Whether a planner reference is an import spec (`module:Class`, `file.py:Class`), not a name."""
    return ":" in text


def canonical_spec(spec: str) -> str:
    """The spec with a file made absolute, so that it means the same from any directory (a worker)."""
    target, _, class_name = spec.rpartition(":")
    return f"{Path(target).resolve()}:{class_name}" if _is_file(target) else spec


def import_planner(spec: str) -> type[Planner]:
    """The planner class an import spec names, imported and checked (PlannerError if it cannot be)."""
    target, _, class_name = spec.rpartition(":")
    if not target or not class_name:
        raise PlannerError(f"{spec}: not module:Class or path/to/file.py:Class")
    if _is_file(target) and not Path(target).is_file():
        raise PlannerError(f"{spec}: no such file")
    try:
        module = _import_file(Path(target)) if _is_file(target) else _import_module(target)
    except Exception as exc:  # anything the user's module raises on import
        raise PlannerError(f"{spec}: cannot import {target}: {type(exc).__name__}: {exc}") from exc
    cls = getattr(module, class_name, None)
    if cls is None:
        raise PlannerError(f"{spec}: {target} has no {class_name}")
    problem = planner_problem(cls)
    if problem:
        raise PlannerError(f"{spec}: {problem}")
    return cls


def _is_file(target: str) -> bool:
    return target.endswith(".py") or "/" in target or os.sep in target


def _import_module(name: str) -> ModuleType:
    """Import a module as `python -m` finds it: the current directory first."""
    here = os.getcwd()
    if not sys.path or sys.path[0] not in (here, ""):
        sys.path.insert(0, here)
    return importlib.import_module(name)


def _import_file(path: Path) -> ModuleType:
    """Import a Python file as a module of its own (see FILE_MODULE_PREFIX)."""
    path = path.resolve()
    name = FILE_MODULE_PREFIX + re.sub(r"\W", "_", path.stem)
    loaded = sys.modules.get(name)
    if loaded is not None:
        if Path(getattr(loaded, "__file__", "")) == path:
            return loaded
        raise ImportError(f"another planner file named {path.name} is already loaded")
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"{path.name} is not a Python source file (.py)")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up while the class is made
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module
