"""Writing run outputs: every file appears complete under its name, or not at all."""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from pathlib import Path

from vplane_mj.errors import VPlaneError


def prepare_out_dir(path: Path, create: bool) -> Path:
    """Check that `path` is a writable directory (creating it only when `create`)."""
    if create and not path.exists():
        try:
            path.mkdir(parents=True)
        except OSError as exc:
            raise VPlaneError(f"{path}: cannot create the output directory: {exc.strerror}") from exc
    if not path.is_dir():
        reason = "is not a directory" if path.exists() else "no such directory"
        raise VPlaneError(f"{path}: output directory: {reason}")
    if not os.access(path, os.W_OK | os.X_OK):
        raise VPlaneError(f"{path}: output directory is not writable")
    return path


def write_atomically(path: Path, write: Callable[[Path], None]) -> Path:
    """Let `write` fill a temporary file beside `path`, then rename it into place."""
    temporary = path.with_name(f".{path.name}.partial")
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
