"""The planners a scenario can name, by name, each a `Planner` class.

Three kinds: the built-in planners; the installed entry points of the group
`vplane_mj.planners` (`name = "module:Class"`), listed from the installed packages' metadata
without importing anything until the planner is used; and the classes registered in this
process (`register_planner`, `load_planner`, or `--planner module:Class` on the command line).
A module is imported when its planner is first looked up, not before: a run loads only the
planner it uses (some need scipy, whose import costs more than a short run's loop).
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from vplane_mj.errors import did_you_mean
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.planning.protocol.params import PlannerInfo
from vplane_mj.planning.protocol.plugins import PlannerError, canonical_spec, import_planner, planner_problem

if TYPE_CHECKING:
    from importlib.metadata import EntryPoint

BUILT_IN: dict[str, tuple[str, str]] = {
    "apf": ("apf", "ApfPlanner"),
    "vplane": ("vplane", "VPlanePlanner"),
    "vplane_plus": ("vplane_plus", "VPlanePlusPlanner"),
    "vobs": ("vobs", "VobsPlanner"),
    "vfh": ("vfh", "VfhPlanner"),
    "bug2": ("bug2", "Bug2Planner"),
    "dwa": ("dwa", "DwaPlanner"),
}
"""Planner name: (its module in vplane_mj.planning, its class)."""

ENTRY_POINT_GROUP = "vplane_mj.planners"
"""The entry point group of installed planners: `name = "module:Class"`."""


def _qualified(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


class _Planners(Mapping[str, type[Planner]]):
    """Planner name -> class: built-in, installed and registered ones, each imported on first use."""

    def __init__(self) -> None:
        self._classes: dict[str, type[Planner]] = {}
        self._registered: list[str] = []
        self._specs: dict[str, type[Planner]] = {}
        self._command_specs: dict[str, str | None] = {}
        self._installed: dict[str, EntryPoint] | None = None

    def installed(self) -> dict[str, EntryPoint]:
        """The entry points of ENTRY_POINT_GROUP by name (read once; nothing is imported). An
        entry point with a built-in planner's name is left out: the built-in planner keeps it."""
        if self._installed is None:
            from importlib.metadata import entry_points

            found = entry_points(group=ENTRY_POINT_GROUP)
            self._installed = {ep.name: ep for ep in found if ep.name not in BUILT_IN}
        return self._installed

    def __getitem__(self, name: str) -> type[Planner]:
        cls = self._classes.get(name)
        if cls is None:
            if name in BUILT_IN:
                module_name, class_name = BUILT_IN[name]
                module = importlib.import_module(f"vplane_mj.planning.planners.{module_name}")
                cls = getattr(module, class_name)
            elif isinstance(name, str) and name in self.installed():
                cls = _load_entry_point(self.installed()[name])
            else:
                raise KeyError(name)
            self._classes[name] = cls
        return cls

    def __contains__(self, name: object) -> bool:
        return (
            name in BUILT_IN or name in self._classes or (isinstance(name, str) and name in self.installed())
        )

    def __iter__(self) -> Iterator[str]:
        return iter(dict.fromkeys([*BUILT_IN, *sorted(self.installed()), *self._registered]))

    def __len__(self) -> int:
        return sum(1 for _ in self)

    def register(self, cls: type[Planner], source: str | None = None) -> type[Planner]:
        """Make `cls` a planner that scenarios can name by `cls.name` (PlannerError if it cannot
        be; the message names `source`, by default the class)."""
        where = source or getattr(cls, "__qualname__", repr(cls))
        problem = planner_problem(cls)
        if problem:
            raise PlannerError(f"{where}: {problem}")
        name = cls.name
        if name in BUILT_IN:
            raise PlannerError(f"{where}: its name {name!r} is a built-in planner's")
        known = self._classes.get(name)
        if known is cls:
            return cls
        if known is not None:
            raise PlannerError(f"{where}: the name {name!r} is taken by {_qualified(known)}")
        entry_point = self.installed().get(name)
        if entry_point is not None and entry_point.value != _qualified(cls):
            taken = f"the installed planner {name} = {entry_point.value}"
            raise PlannerError(f"{where}: the name {name!r} is taken by {taken}")
        self._classes[name] = cls
        self._registered.append(name)
        self._command_specs[name] = _command_line_spec(cls)
        return cls

    def load(self, spec: str) -> type[Planner]:
        """Import, check and register the class an import spec names, once per process."""
        key = canonical_spec(spec)
        cls = self._specs.get(key)
        if cls is None:
            cls = self.register(import_planner(spec), source=spec)
            self._specs[key] = cls
            self._command_specs[cls.name] = key
        return cls

    def for_worker(self, name: str) -> WorkerPlanner | None:
        """What another process (a sweep's worker) registers to know planner `name`: None for a
        built-in or installed planner, which every process knows by its name; the import spec of
        a class from a module or a planner file; the class itself when it comes from the script
        being run (`__main__`), which a worker must not import: importing a script runs it."""
        if name not in self._registered:
            return None
        cls = self._classes[name]
        if cls.__module__ == "__main__" and "<locals>" not in cls.__qualname__:
            return cls
        return self._command_specs[name]

    def command_line_spec(self, name: str) -> str | None:
        """The `--planner` import spec that names registered planner `name` on the command line
        (for a class of the script being run, the script's file), or None when there is none."""
        return self._command_specs.get(name)


WorkerPlanner = str | type[Planner]
"""A registered planner as a sweep's job carries it to its worker: an import spec, or a class
of the calling script (`__main__`). Such a class travels by reference to the local pool's
workers, forked with it already registered, and by value (cloudpickle) to Dask's workers."""


def _command_line_spec(cls: type) -> str | None:
    """`module:Class` for a class another process can import; for a class of the script being
    run (`__main__`), that script's file; None when neither exists (an interactive session, a
    class defined in a function)."""
    if "<locals>" in cls.__qualname__:
        return None
    if cls.__module__ != "__main__":
        return _qualified(cls)
    script = getattr(sys.modules["__main__"], "__file__", None)
    return f"{Path(script).resolve()}:{cls.__qualname__}" if script else None


def _load_entry_point(entry_point: EntryPoint) -> type[Planner]:
    """The class an installed entry point names, imported and checked."""
    where = f"installed planner {entry_point.name} = {entry_point.value}"
    try:
        cls = entry_point.load()
    except Exception as exc:  # anything the installed module raises on import
        raise PlannerError(f"{where}: cannot import it: {type(exc).__name__}: {exc}") from exc
    problem = planner_problem(cls)
    if problem:
        raise PlannerError(f"{where}: {problem}")
    if cls.name != entry_point.name:
        raise PlannerError(f"{where}: the class's name is {cls.name!r}, not the entry point's")
    return cls


PLANNERS = _Planners()

DEFAULT_PLANNER = "vplane"


def register_planner(cls: type[Planner]) -> type[Planner]:
    """Register a planner class under its `name` in this process (also as a class decorator).

    Args:
        cls: A `Planner` subclass with `name`, `summary`, `citation` and `Params` set.

    Returns:
        The class itself, so that it works as a decorator.

    Raises:
        PlannerError: It is not a valid planner, or its name is a built-in, installed or
            other registered planner's.
    """
    return PLANNERS.register(cls)


def load_planner(spec: str) -> type[Planner]:
    """Import and register the planner class an import spec names (once per process).

    Args:
        spec: `module:Class` (the module looked up as `python -m` would, the current
            directory first) or `path/to/file.py:Class`.

    Returns:
        The class, registered under its `name`.

    Raises:
        PlannerError: The module or class cannot be imported, is not a valid planner, or its
            name is taken.
    """
    return PLANNERS.load(spec)


def command_line_spec(name: str) -> str | None:
    """The `--planner` import spec of registered planner `name`, or None (see `_Planners`)."""
    return PLANNERS.command_line_spec(name)


def for_worker(name: str) -> WorkerPlanner | None:
    """What a worker process registers to know planner `name` (None: nothing, it knows it)."""
    return PLANNERS.for_worker(name)


def register_in_worker(planner: WorkerPlanner) -> type[Planner]:
    """In a worker process: register what `for_worker` gave (a class already registered here,
    as in a forked worker, is left as it is)."""
    return load_planner(planner) if isinstance(planner, str) else register_planner(planner)


def unknown_planner(name: str, note: str = "") -> str:
    """Why `name` names no planner: the planners available, and the closest name to it."""
    known = ", ".join(sorted(PLANNERS))
    return f"unknown planner {name!r}{note}; available: {known}{did_you_mean(name, PLANNERS)}"


def planner_info(name: str) -> PlannerInfo:
    """Name, summary, citation and parameter table of planner `name` (KeyError when there is none)."""
    return PLANNERS[name].info()


def make_planner(name: str, params: Mapping[str, object], robot: RobotBody | float) -> Planner:
    """A fresh planner, its parameters resolved against the defaults (each checked).

    Args:
        name: The planner's name (built-in, installed or registered).
        params: Parameter overrides by name, as a scenario's `[planner]` table holds them.
        robot: The robot's body, or a round robot's radius (m).

    Returns:
        The planner, ready for its first `step`.

    Raises:
        KeyError: No planner has that name.
        ParamError: An unknown parameter or a bad value.
    """
    return PLANNERS[name].build(params, robot)
