"""Exclusive locks on outputs, so that two processes never write the same files at once.

A lock is a file beside the outputs (`.NAME.lock`) on which its holder keeps an advisory
`flock`: the kernel releases it when the holder exits, however it exits, so a lock file that a
killed process left behind is stale and simply taken over. The holder writes who it is (pid,
host, start time, command) into the file, for the message of the process it keeps out.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import socket
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from vplane_mj.errors import VPlaneError, readable


class OutputBusy(VPlaneError):
    """Another process holds the lock on these outputs."""


@contextlib.contextmanager
def exclusive(
    path: Path,
    what: str,
    remedy: str,
    wait: bool = False,
    on_wait: Callable[[str], object] | None = None,
) -> Iterator[None]:
    """Hold the lock file `path` (`.NAME.lock` beside the outputs it guards) for the block.

    Held by another process, an OutputBusy names `what`, the holder and the `remedy`; with `wait`,
    the block waits for the holder to finish instead (after calling `on_wait` with a line that
    says whom it waits for). The lock file is removed when the block ends.
    """
    descriptor = _acquire(path, what, remedy, wait, on_wait)
    try:
        os.ftruncate(descriptor, 0)
        os.write(descriptor, json.dumps(_me()).encode("utf-8"))
        yield
    finally:
        with contextlib.suppress(OSError):
            path.unlink()  # before the unlock: a process that opens the path next makes a new file
        os.close(descriptor)


def _acquire(path: Path, what: str, remedy: str, wait: bool, on_wait: Callable[[str], object] | None) -> int:
    """A descriptor of the lock file `path` with the lock held (the file still at `path`)."""
    while True:
        try:
            descriptor = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise VPlaneError(f"{readable(path)}: cannot create the lock file: {exc.strerror}") from exc
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(descriptor)
            if not wait:
                os.close(descriptor)
                raise OutputBusy(f"{what}: in use by {holder}; {remedy}") from None
            if on_wait is not None:
                on_wait(f"{what}: waiting for {holder} to end")
            fcntl.flock(descriptor, fcntl.LOCK_EX)
        if _still_at(descriptor, path):
            return descriptor
        os.close(descriptor)  # the holder removed the file while we waited: lock the new one


def _still_at(descriptor: int, path: Path) -> bool:
    """Whether the open file is still the one at `path` (its holder did not remove it)."""
    try:
        return os.path.samestat(os.fstat(descriptor), os.stat(path))
    except FileNotFoundError:
        return False


def _me() -> dict[str, object]:
    """Who holds a lock: this process."""
    return {
        "pid": os.getpid(),
        "host": socket.gethostname(),
        "since": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
        "command": " ".join(sys.argv),
    }


HOLDER_TEXT_MAX = 200
"""The longest command line quoted from a lock file (characters)."""


def _holder(descriptor: int) -> str:
    """The holder of a lock as its file names it: "another process" when it cannot tell."""
    try:
        info = json.loads(os.pread(descriptor, 4096, 0).decode("utf-8"))
        command = str(info["command"])[:HOLDER_TEXT_MAX]
        return f"pid {int(info['pid'])} on {info['host']} since {info['since']} ({command})"
    except (OSError, ValueError, KeyError, TypeError):
        return "another process"
