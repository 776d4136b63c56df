"""Every compiled kernel of the project (numba, no fastmath): the loops a control tick spends its
time in, each written once, here. `maps/` serves the local map (the grid, its distance
transform and way search costs, the histogram, the echo points), `motion/` the motion (arcs,
the drive model, the governor's outline checks and memory, the way, evasion, the fields);
`tracking` the tracker, `laser` the laser's ray cast, `geometry` the path simplifier and the
moving obstacles.

Every module of this package imports numba, which takes about 0.3 s a process; the modules
that use them import them only where a run needs them (a map's constructor, a planner's first
step), so `import vplane_mj`, `vplane-mj check` and `vplane-mj list` never load numba. They
use the C library's `atan2`, `sin`, `hypot` and the like, as numpy does on a CPU without
AVX-512 (numpy's own AVX-512 routines may differ in the last bit).

The kernels compile on their first call and are cached on disk, in a directory named by a
digest of this package's sources (`cache_path`): a kernel that calls one of another module is
compiled again when either changes, where numba's own cache, which checks only the file of
the function it loads, would run the stale machine code of a caller whose callee was edited.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba
from numba.core import config as numba_config

from vplane_mj.files import cache_dir

SOURCES = Path(__file__).resolve().parent
"""The package whose sources name the cache."""


def sources_digest() -> str:
    """SHA-256 (hex) of every source file of this package (its path and bytes) and numba's
    version: any edit of any kernel gives a new digest."""
    digest = hashlib.sha256(numba.__version__.encode())
    for path in sorted(SOURCES.rglob("*.py")):
        digest.update(path.relative_to(SOURCES).as_posix().encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()


def cache_path() -> Path:
    """Where the compiled kernels are kept: `__pycache__/kernels-DIGEST` in this package where it
    can be written, else `kernels-DIGEST` in the project's cache directory."""
    name = f"kernels-{sources_digest()[:16]}"
    in_tree = SOURCES / "__pycache__"
    if os.access(SOURCES, os.W_OK) and (not in_tree.exists() or os.access(in_tree, os.W_OK)):
        return in_tree / name
    return cache_dir() / name


CACHE_PATH = cache_path()


def njit(function: Callable | None = None, **options: Any) -> Any:
    """`numba.njit(cache=True, **options)`, cached in CACHE_PATH (as `@njit` or `@njit(...)`)."""

    def compile_cached(py_function: Callable) -> Any:
        chosen = numba_config.CACHE_DIR  # type: ignore[attr-defined]  # numba sets its config at run time
        numba_config.CACHE_DIR = str(CACHE_PATH)  # type: ignore[attr-defined]  # read by the dispatcher
        try:
            return numba.njit(cache=True, **options)(py_function)
        finally:
            numba_config.CACHE_DIR = chosen  # type: ignore[attr-defined]

    return compile_cached if function is None else compile_cached(function)
