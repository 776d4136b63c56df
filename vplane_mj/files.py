"""The project's files: the shipped data (`models/`, `scenarios/`), and run outputs written so
that every file appears complete under its name, or not at all."""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
import secrets
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

from vplane_mj.errors import VPlaneError

_PACKAGE_DIR = Path(__file__).resolve().parent

DEFAULT_OUT = Path("logs")
"""Where runs and sweeps write their files unless told otherwise."""


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
