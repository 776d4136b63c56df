"""The process's side of the terminal: SIGINT and SIGTERM as an exception, so a run can close its
log cleanly before exiting; and progress bars on stderr (rich's, on a terminal; a line every tenth
of the way otherwise, as a log file wants)."""

from __future__ import annotations

import contextlib
import signal
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any


class Interrupted(Exception):
    """The process received SIGINT or SIGTERM; `exit_status` is the conventional 128 + signal.

    `written` holds the files that the interrupted work had written whole, by role (as
    `RunRecord.files`), for the message.
    """

    def __init__(self, signum: int):
        self.signum = signum
        self.exit_status = 128 + signum
        self.written: dict[str, Path] = {}
        super().__init__(signal.Signals(signum).name)


def _raise(signum: int, _frame: object) -> None:
    raise Interrupted(signum)


@contextlib.contextmanager
def signals_raise_interrupted() -> Iterator[None]:
    """Within the block, SIGINT and SIGTERM raise Interrupted; the old handlers come back after."""
    previous = {sig: signal.signal(sig, _raise) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


class Progress:
    """A progress bar of `total` items (`unit`, e.g. "runs"), `done` of them already, on stderr:
    with its ETA on a terminal; a line per tenth of the way when stderr is not one. A context
    manager: the bar closes at the end of the block."""

    def __init__(self, label: str, total: int, unit: str, done: int = 0):
        self.label, self.total, self.unit, self.done = label, total, unit, done
        self._bar: Any = None
        self._task: Any = None
        self._last_tenth = 10 * done // max(total, 1)

    def __enter__(self) -> Progress:
        if sys.stderr.isatty():
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )
            from rich.progress import Progress as Bar

            self._bar = Bar(
                TextColumn("{task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TextColumn(self.unit),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                transient=False,
            )
            self._bar.start()
            self._task = self._bar.add_task(self.label, total=self.total, completed=self.done)
        return self

    def advance(self) -> None:
        """One more item done."""
        self.done += 1
        if self._bar is not None:
            self._bar.advance(self._task)
        elif (tenth := 10 * self.done // max(self.total, 1)) != self._last_tenth:
            self._last_tenth = tenth
            print(f"{self.label}: {self.done}/{self.total} {self.unit}", file=sys.stderr, flush=True)

    def __exit__(self, *exc_info: object) -> None:
        if self._bar is not None:
            self._bar.stop()
