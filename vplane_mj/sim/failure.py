"""A run that ended without a summary of its own: why (the exception it raised and where, or
its worker process dying), as one line for a row and the whole traceback."""

from __future__ import annotations

import traceback
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path
from types import TracebackType

FRAMES_IN_MESSAGE = 3
"""How many of the innermost frames of a traceback a failure's message names."""
SOURCE_ROOT = Path(__file__).resolve().parent.parent.parent
"""Paths below this directory (the package's parent) are shown relative to it."""


class FailureKind(StrEnum):
    """Why a run of a sweep ended without a summary."""

    EXCEPTION = "exception"
    """The run raised an exception."""
    WORKER_DIED = "worker_died"
    """The process running it died (killed by a signal such as the OOM killer's, or exited)."""


@dataclass(frozen=True)
class RunFailure:
    """A run that ended without a summary: one line for its row and, when it raised, the
    whole traceback."""

    kind: FailureKind
    message: str
    traceback: str = ""


def failure_of(
    exc: BaseException, trace: TracebackType | None = None, kind: FailureKind = FailureKind.EXCEPTION
) -> RunFailure:
    """The failure of a run that raised `exc`; `trace` when it is not `exc.__traceback__`.

    Its message, e.g. `ValueError: bad (at vplane_mj/sim.py:210 in run_tick, from
    vplane_mj/sim.py:236 in run_scenario)`: the exception and the innermost frames.
    """
    trace = trace if trace is not None else exc.__traceback__
    text = "".join(traceback.format_exception_only(type(exc), exc)).strip()
    frames = traceback.extract_tb(trace)[-FRAMES_IN_MESSAGE:]
    places = [f"{_shown(frame.filename)}:{frame.lineno} in {frame.name}" for frame in reversed(frames)]
    message = f"{text} (at {', from '.join(places)})" if places else text
    return RunFailure(kind, message, "".join(traceback.format_exception(type(exc), exc, trace)))


def _shown(filename: str) -> str:
    """A source file's path relative to SOURCE_ROOT when it lies below it."""
    path = Path(filename)
    return str(path.relative_to(SOURCE_ROOT)) if path.is_relative_to(SOURCE_ROOT) else filename
