"""The benchmark scripts' command lines, checked before any work.

Each option is checked by its argparse type, so a bad value is refused as argparse refuses any
(the usage, "argument --count: at least 1, not 0", exit 2) before a file is written.
`refusing` wraps a script's `main`: the VPlaneError of input met on the way (an output
directory that cannot be written, a scenario that does not load, a journal that is not there)
becomes one line, "error: ...", and exit 2, not a traceback.
"""

from __future__ import annotations

import argparse
import functools
import math
import sys
from collections.abc import Callable, Collection
from pathlib import Path
from typing import Protocol

from vplane_mj.bench.sweep import parse_seeds
from vplane_mj.errors import VPlaneError
from vplane_mj.planning.protocol.registry import PLANNERS
from vplane_mj.scenario import resolve_path


class Main(Protocol):
    """A script's `main`: its exit status for the command line `argv` (None: the process's)."""

    def __call__(self, argv: list[str] | None = None) -> int: ...


def whole(least: int) -> Callable[[str], int]:
    """An option's type: a whole number of at least `least`."""

    def checked(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"a whole number, not {text!r}") from None
        if value < least:
            raise argparse.ArgumentTypeError(f"at least {least}, not {value}")
        return value

    return checked


def number(least: float, *, above: bool = False, most: float = math.inf) -> Callable[[str], float]:
    """An option's type: a finite number of at least `least` (greater, when `above`) and at
    most `most`."""
    bounds = f"{'greater than' if above else 'at least'} {least:g}" + (
        f" and at most {most:g}" if most < math.inf else ""
    )

    def checked(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"a number, not {text!r}") from None
        if not math.isfinite(value) or value < least or (above and value == least) or value > most:
            raise argparse.ArgumentTypeError(f"a finite number {bounds}, not {text!r}")
        return value

    return checked


positive = number(0.0, above=True)
"""An option's type: a finite number greater than 0."""
non_negative = number(0.0)
"""An option's type: a finite number of at least 0."""


def numbers(least: float, *, above: bool = False, most: float = math.inf) -> Callable[[str], list[float]]:
    """An option's type: comma-separated numbers, each as `number(least, above=above, most=most)`."""
    each = number(least, above=above, most=most)

    def checked(text: str) -> list[float]:
        return [each(part.strip()) for part in text.split(",")]

    return checked


positives = numbers(0.0, above=True)
"""An option's type: comma-separated finite numbers, each greater than 0."""


def names(allowed: Collection[str], what: str) -> Callable[[str], list[str]]:
    """An option's type: comma-separated names, each one of `allowed` (`what` they are) and
    each once."""

    def checked(text: str) -> list[str]:
        chosen = [part.strip() for part in text.split(",")]
        for index, name in enumerate(chosen):
            if name not in allowed:
                known = ", ".join(sorted(allowed))
                raise argparse.ArgumentTypeError(f"unknown {what} {name!r}; available: {known}")
            if name in chosen[:index]:
                raise argparse.ArgumentTypeError(f"{what} {name!r} given twice")
        return chosen

    return checked


planners = names(PLANNERS, "planner")
"""An option's type: comma-separated names of registered planners."""


def planner(text: str) -> str:
    """An option's type: the name of a registered planner."""
    if "," in text:
        raise argparse.ArgumentTypeError(f"one planner, not {text!r}")
    return planners(text)[0]


def seeds(text: str) -> list[int]:
    """An option's type: run seeds as `vplane-mj bench` takes them ("0-19", "7", "0,2,5-7")."""
    try:
        return parse_seeds(text)
    except VPlaneError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--seeds: ")) from None


def scenario(text: str) -> str:
    """An option's type: a scenario file or a built-in scenario's name, as given."""
    try:
        resolve_path(text)
    except VPlaneError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def add_world_sweep(
    parser: argparse.ArgumentParser, worlds: tuple[int, str], run_seeds: str, out: str
) -> None:
    """The options of a sweep of runs over generated worlds: --count (`worlds`: the default and
    what they are), --world-seed, --seeds (`run_seeds` by default), --noise (the laser's, m),
    --jobs and --out (logs/`out` by default)."""
    parser.add_argument("--count", type=whole(1), default=worlds[0], help=worlds[1])
    parser.add_argument("--world-seed", type=whole(0), default=0, help="seed of the worlds")
    parser.add_argument("--seeds", type=seeds, default=run_seeds, help="run seeds: 0-4, 7 or 0,2,5-7")
    parser.add_argument("--noise", type=non_negative, default=0.01, help="laser range noise (m)")
    parser.add_argument("--jobs", type=whole(1), default=2, help="worker processes")
    parser.add_argument("--out", type=Path, default=Path("logs") / out)


def refusing(main: Main) -> Main:
    """`main` with the VPlaneError of bad input told in one line, "error: ...", and exit 2."""

    @functools.wraps(main)
    def checked(argv: list[str] | None = None) -> int:
        try:
            return main(argv)
        except VPlaneError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2

    return checked
