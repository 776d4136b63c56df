"""A small on-disk cache of JSON values keyed by content, shared by processes and sweeps.

Where: the directory named by the environment variable VPLANE_MJ_CACHE, else
`$XDG_CACHE_HOME/vplane-mj`, else `~/.cache/vplane-mj`. Each entry is one JSON file named
by the SHA-256 of its key, holding the key and the value. It is written under a
temporary name and renamed into place, so a reader finds a whole entry or none, and a
process killed while writing leaves no damaged entry. Processes that miss the same key
at once take a lock file in turn (`fcntl.flock`, released by the system even if its
holder is killed), so the value is computed once. Any failure to read or write the
cache (no such directory, no permission, a damaged file) falls back to computing the
value: the cache never changes a result, only how often it is computed.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from vplane_mj.errors import VPlaneError
from vplane_mj.files import CACHE_ENV as CACHE_ENV
from vplane_mj.files import cache_dir, exclusive


def cached(namespace: str, key: dict[str, Any], compute: Callable[[], Any]) -> Any:
    """The value stored under `key` in `namespace`, else `compute()`, stored for next time."""
    text = json.dumps(key, sort_keys=True, allow_nan=False)
    path = cache_dir() / namespace / f"{hashlib.sha256(text.encode()).hexdigest()}.json"
    found, value = _read(path, key)
    if found:
        return value
    with _locked(path.with_suffix(".lock")):
        found, value = _read(path, key)  # another process may have stored it meanwhile
        if not found:
            value = compute()
            _write(path, key, value)
    return value


def _read(path: Path, key: dict[str, Any]) -> tuple[bool, Any]:
    try:
        entry = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False, None
    if not isinstance(entry, dict) or entry.get("key") != key or "value" not in entry:
        return False, None
    return True, entry["value"]


def _write(path: Path, key: dict[str, Any], value: Any) -> None:
    with contextlib.suppress(OSError, ValueError):
        text = json.dumps({"key": key, "value": value}, sort_keys=True, allow_nan=False)
        handle, temporary = tempfile.mkstemp(prefix=f".{path.stem}.", dir=path.parent)
        try:
            with os.fdopen(handle, "w", encoding="utf-8") as stream:
                stream.write(text)
            os.replace(temporary, path)
        except BaseException:
            os.unlink(temporary)
            raise


@contextlib.contextmanager
def _locked(path: Path) -> Iterator[None]:
    """Hold the lock file `path` (created with its directory; `files.exclusive`, waiting for
    another holder); no lock where that fails."""
    with contextlib.ExitStack() as stack:
        with contextlib.suppress(OSError, VPlaneError):
            path.parent.mkdir(parents=True, exist_ok=True)
            stack.enter_context(exclusive(path, "the reference-path cache", "", wait=True))
        yield
