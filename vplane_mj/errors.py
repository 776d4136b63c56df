"""The project's exceptions: every user-facing failure derives from VPlaneError. And the closest
known name to one the user mistyped, for a message's "did you mean ...?": one helper for every
message about an unknown name (planners, planner parameters, scenario keys, obstacle kinds,
scenarios, families, robot profiles), so that each says it the same way. And how a message
shows what came from outside: a file's path readably (`readable`), a name or a text read from a
file quoted and cut to a readable length (`shown`), any other long text cut (`cut`)."""

from __future__ import annotations

import difflib
import os
from collections.abc import Iterable

CLOSENESS = 0.6
"""The least `difflib.SequenceMatcher` ratio (0 to 1) at which a known name is suggested."""
SHOWN_CHARS = 80
"""The most characters of a name or a text from an input a message shows."""


class VPlaneError(Exception):
    """An error a user can act on; the command line prints it and exits with status 2."""


class ScenarioError(VPlaneError):
    """Invalid scenario input: names the file, the key path and the reason; or, when an
    override (`--set KEY=VALUE`, `--seed N`, the Python API's `overrides`) set the key, that
    override (`origin`) first.

    Args:
        source: The file (or `<code>`) the scenario came from.
        key: The key path (`world.obstacles[2].radius`), empty for the document itself.
        reason: Why it is refused.
        origin: The override that set the key, as its errors name it; empty for the file.
    """

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

    def __reduce__(self):
        """Rebuilt from its arguments, so that it crosses a process boundary (a sweep's worker)."""
        return type(self), (self.source, self.key, self.reason, self.origin)


class WorldFileError(VPlaneError):
    """An imported world file (SDF) that cannot be converted: names the file, the element and
    the reason."""

    def __init__(self, source: str, element: str, reason: str):
        self.source = source
        self.element = element
        self.reason = reason
        shown_source = readable(source)
        super().__init__(f"{shown_source}: {element}: {reason}" if element else f"{shown_source}: {reason}")

    def __reduce__(self):
        """Rebuilt from its arguments, so that it crosses a process boundary (a sweep's worker)."""
        return type(self), (self.source, self.element, self.reason)


def closest(word: str, known: Iterable[str]) -> str | None:
    """The known name most like `word` (case aside), or None when none is close enough."""
    names = {name.lower(): name for name in known if isinstance(name, str)}
    matches = difflib.get_close_matches(word.lower(), list(names), n=1, cutoff=CLOSENESS)
    return names[matches[0]] if matches and names[matches[0]] != word else None


def did_you_mean(word: str, known: Iterable[str]) -> str:
    """The end of a message about an unknown name: `; did you mean 'x'?` with the known name
    closest to `word`, or "" when none is close."""
    match = closest(word, known)
    return f"; did you mean {match!r}?" if match is not None else ""


def readable(text: str | os.PathLike[str]) -> str:
    """`text` (a file's path) as any terminal prints it: the bytes of a name that are not UTF-8
    (which Python holds as lone surrogates) as `\\xNN`, and every other character that cannot
    be printed (a control, a lone surrogate of no byte) as Python's backslash escape."""
    text = without_surrogates(os.fspath(text))
    return "".join(char if char.isprintable() else repr(char)[1:-1] for char in text)


def without_surrogates(text: str) -> str:
    """`text` with the lone surrogates Python holds for bytes of a name that are not UTF-8 as
    `\\xNN`, and any other lone surrogate as `\\udcNN`: text that encodes as UTF-8."""
    try:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    except UnicodeEncodeError:  # a surrogate that stands for no byte
        return text.encode("utf-8", "backslashreplace").decode("utf-8")


def _rest(text: str) -> str:
    """What `cut` and `shown` put after the first SHOWN_CHARS characters of a longer text."""
    return "" if len(text) <= SHOWN_CHARS else f"... ({len(text)} characters)"


def cut(text: str) -> str:
    """`text`, or its first SHOWN_CHARS characters, an ellipsis and its length."""
    return text[:SHOWN_CHARS] + _rest(text)


def shown(text: str) -> str:
    """A name or a text read from a file, for a message: quoted with Python's repr (so with
    backslash escapes for what cannot be printed), cut as `cut` cuts it."""
    return repr(text[:SHOWN_CHARS]) + _rest(text)
