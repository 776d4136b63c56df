"""SIGINT and SIGTERM as an exception, so a run can close its log cleanly before exiting."""

from __future__ import annotations

import contextlib
import signal
from collections.abc import Iterator
from pathlib import Path


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
