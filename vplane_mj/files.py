"""The project's files: the shipped data (`models/`, `scenarios/`), and run outputs written so
that every file (or directory) appears complete under its name, or not at all, by one writer
at a time.

Exclusive locks keep two processes from writing the same outputs at once. A lock is a file
beside the outputs (`.NAME.lock`) on which its holder keeps an advisory `flock`: the kernel
releases it when the holder exits, however it exits, so a lock file that a killed process left
behind is stale and simply taken over. The holder writes who it is (pid, host, start time,
command) into the file, for the message of the process it keeps out.
"""

from __future__ import annotations

import contextlib
import csv
import fcntl
import io
import json
import os
import secrets
import shutil
import socket
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from vplane_mj.errors import VPlaneError, readable

_PACKAGE_DIR = Path(__file__).resolve().parent

DEFAULT_OUT = Path("logs")
"""Where runs and sweeps write their files unless told otherwise."""
CACHE_ENV = "VPLANE_MJ_CACHE"
"""The environment variable that names the project's cache directory (`cache_dir`)."""


def cache_dir() -> Path:
    """The project's cache directory: the one VPLANE_MJ_CACHE names, else
    `$XDG_CACHE_HOME/vplane-mj`, else `~/.cache/vplane-mj`."""
    chosen = os.environ.get(CACHE_ENV)
    if chosen:
        return Path(chosen)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "vplane-mj"


def prepare_out_dir(path: Path) -> Path:
    """`path` as a directory that files can be written into, created with its parents if missing.

    Writability is tried with a temporary file, so that a read-only file system or a
    directory that even root cannot write (such as /sys) is found before any work;
    a VPlaneError names the directory and the reason.
    """
    if not path.is_dir():
        if path.exists():
            raise VPlaneError(f"{path}: output directory: is not a directory")
        try:
            path.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise VPlaneError(f"{path}: cannot create the output directory: {exc.strerror}") from exc
    try:
        with tempfile.TemporaryFile(dir=path, prefix=".vplane-mj-probe-"):
            pass
    except OSError as exc:
        raise VPlaneError(f"{path}: output directory is not writable: {exc.strerror}") from exc
    return path


@contextlib.contextmanager
def output_directory(path: Path) -> Iterator[Path]:
    """`prepare_out_dir(path)` for a command: if the command then fails on bad input (a
    VPlaneError), the directories made here are removed again while they are empty, so
    that a rejected command leaves nothing behind."""
    missing = [parent for parent in (path, *path.parents) if not parent.exists()]
    try:
        yield prepare_out_dir(path)
    except VPlaneError:
        for directory in missing:  # deepest first
            with contextlib.suppress(OSError):
                directory.rmdir()
        raise


def partial_path(path: Path) -> Path:
    """A temporary name beside `path` that no other writer uses: `.NAME.PID-RANDOM.partial`."""
    return path.with_name(f".{path.name}.{os.getpid()}-{secrets.token_hex(4)}.partial")


def write_atomically(path: Path, write: Callable[[Path], object]) -> Path:
    """Let `write` fill a temporary file beside `path` (`partial_path`), then rename it into place
    (what `write` returns is ignored); the temporary file is removed if anything fails."""
    temporary = partial_path(path)
    try:
        write(temporary)
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    return path


def write_directory_atomically(path: Path, write: Callable[[Path], object]) -> Path:
    """Let `write` make the directory it is given, named as `path` inside a temporary directory
    beside it (`partial_path`), then move that into place: a directory already at `path` is
    replaced, and is gone only once the new one is whole. The temporary directory is removed
    whatever happens, so a failure leaves `path` as it was."""
    temporary = partial_path(path)
    try:
        temporary.mkdir()
        made = temporary / path.name
        write(made)
        replaced = temporary / f"{path.name}.replaced"
        if path.is_dir():
            os.replace(path, replaced)
        try:
            os.replace(made, path)
        except BaseException:
            if replaced.exists():
                os.replace(replaced, path)
            raise
    finally:
        shutil.rmtree(temporary, ignore_errors=True)
    return path


def write_json(path: Path, document: dict) -> Path:
    """A JSON document, indented, written atomically."""
    text = json.dumps(document, indent=2, allow_nan=False) + "\n"
    return write_atomically(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def write_csv(path: Path, rows: list[dict], columns: list[str] | tuple[str, ...]) -> Path:
    """`rows` as CSV with a header of `columns` (other keys left out), written atomically."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(columns), extrasaction="ignore")
    writer.writeheader()
    writer.writerows(rows)
    return write_atomically(path, lambda tmp: tmp.write_text(buffer.getvalue(), encoding="utf-8"))


def data_dir(name: str) -> Path:
    """The directory `name` ("models" or "scenarios"): inside the installed wheel, else the repo's."""
    installed = _PACKAGE_DIR / name
    if installed.is_dir():
        return installed
    return _PACKAGE_DIR.parent / name


def model_path(filename: str) -> Path:
    """Path of a shipped MJCF file, e.g. "robot.xml"."""
    return data_dir("models") / filename


class OutputBusy(VPlaneError):
    """Another process holds the lock on these outputs: `run` and `sweep` raise it, naming the
    outputs, the holder and what to do, before anything is written."""


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
