"""Where the shipped data lives: `models/` and `scenarios/`, installed or in a source tree."""

from __future__ import annotations

from pathlib import Path

_PACKAGE_DIR = Path(__file__).resolve().parent


def data_dir(name: str) -> Path:
    """The directory `name` ("models" or "scenarios"): inside the installed wheel, else the repo's."""
    installed = _PACKAGE_DIR / name
    if installed.is_dir():
        return installed
    return _PACKAGE_DIR.parent / name


def model_path(filename: str) -> Path:
    """Path of a shipped MJCF file, e.g. "robot.xml"."""
    return data_dir("models") / filename
