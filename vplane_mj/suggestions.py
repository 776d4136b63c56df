"""The closest known name to one the user mistyped, for a message's "did you mean ...?".

One helper for every message about an unknown name (planners, planner parameters, scenario
keys, obstacle kinds, scenarios, families), so that each says it the same way.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable

CLOSENESS = 0.6
"""The least `difflib.SequenceMatcher` ratio (0 to 1) at which a known name is suggested."""


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
