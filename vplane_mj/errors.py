"""The project's exceptions: every user-facing failure derives from VPlaneError."""

from __future__ import annotations


class VPlaneError(Exception):
    """An error a user can act on; the command line prints it and exits with status 2."""


class ScenarioError(VPlaneError):
    """Invalid scenario input: names the file, the key path and the reason; or, when an
    override (`--set KEY=VALUE`, `--seed N`) set the key, that override (`origin`) first."""

    def __init__(self, source: str, key: str, reason: str, origin: str = ""):
        self.source = source
        self.key = key
        self.reason = reason
        self.origin = origin
        if origin:
            message = f"{origin}: {reason} (applied to {source})"
        else:
            message = f"{source}: {key}: {reason}" if key else f"{source}: {reason}"
        super().__init__(message)


class WorldFileError(VPlaneError):
    """An imported world file (SDF) that cannot be converted: names the file, the element and
    the reason."""

    def __init__(self, source: str, element: str, reason: str):
        self.source = source
        self.element = element
        self.reason = reason
        super().__init__(f"{source}: {element}: {reason}" if element else f"{source}: {reason}")
