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

LLVM compiles them for a generic model of the CPU (`COMPILE_FOR_CPU`), with the instruction set
the CPU has: tuned for the host's own model, the same kernels gave other last bits on two
machines that differ only in it (see `compile_for_generic_cpu`).

Loading a kernel from that cache takes a few milliseconds on its first call in a process. A run
loads the kernels the last runs of its kind used before its loop starts (`preload`), from the
signatures they left in the cache (`remember`), so the loop's wall time holds no loading.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib
import os
import pickle
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import llvmlite.binding
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


COMPILE_FOR_CPU = "generic"
"""The CPU model (LLVM's name) the kernels are compiled for."""


def compile_for_generic_cpu() -> None:
    """Have numba compile for `COMPILE_FOR_CPU` unless the user chose a model (`NUMBA_CPU_NAME`)
    or this process compiled something already (numba then keeps the model it chose).

    Measured on the 308 golden runs: compiled for the host's model (`znver4`) on a CPU with
    AVX-512, six trajectories differed in their last bits from those of a CPU without it;
    compiled for `generic` with the same instructions, none did. numba compiles a process's own
    functions for the same model as these kernels."""
    from numba.core.registry import cpu_target

    if numba_config.CPU_NAME is None and "_toplevel_target_context" not in vars(cpu_target):  # type: ignore[attr-defined]
        numba_config.CPU_NAME = COMPILE_FOR_CPU  # type: ignore[attr-defined]  # numba sets its config at run time


def compiled_for_cpu() -> str:
    """The CPU model (LLVM's name) this process's kernels are compiled for."""
    return numba_config.CPU_NAME or llvmlite.binding.get_host_cpu_name()  # type: ignore[attr-defined]


compile_for_generic_cpu()
CACHE_PATH = cache_path()
DISPATCHERS: dict[str, Any] = {}
"""Every kernel made in this process by `njit`, by its module and name (`module.function`)."""


def njit(function: Callable | None = None, **options: Any) -> Any:
    """`numba.njit(cache=True, **options)`, cached in CACHE_PATH (as `@njit` or `@njit(...)`)."""

    def compile_cached(py_function: Callable) -> Any:
        chosen = numba_config.CACHE_DIR  # type: ignore[attr-defined]  # numba sets its config at run time
        numba_config.CACHE_DIR = str(CACHE_PATH)  # type: ignore[attr-defined]  # read by the dispatcher
        try:
            dispatcher = numba.njit(cache=True, **options)(py_function)
        finally:
            numba_config.CACHE_DIR = chosen  # type: ignore[attr-defined]
        DISPATCHERS[f"{py_function.__module__}.{py_function.__name__}"] = dispatcher
        return dispatcher

    return compile_cached if function is None else compile_cached(function)


def loaded() -> int:
    """How many kernel signatures this process has compiled or loaded."""
    return sum(len(dispatcher.signatures) for dispatcher in DISPATCHERS.values())


def _manifest_path(kind: str) -> Path:
    """Where the kernels that runs of `kind` used are listed (a pickle in CACHE_PATH)."""
    return CACHE_PATH / f"used-{kind}.pickle"


def _manifest(kind: str) -> dict[str, list]:
    """Kernel name -> the signatures runs of `kind` called it with; empty when none is known."""
    try:
        listed = pickle.loads(_manifest_path(kind).read_bytes())
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError, TypeError):
        return {}
    return listed if isinstance(listed, dict) else {}


def preload(kind: str) -> float:
    """Load (or compile) every kernel that the runs of `kind` before this one used, with the
    signatures they called it with; the wall time (s) it took. A kernel renamed or gone since
    is left out."""
    started = time.perf_counter()
    for name, signatures in _manifest(kind).items():
        module, _, function = name.rpartition(".")
        try:
            dispatcher = getattr(importlib.import_module(module), function)
            for signature in signatures:
                dispatcher.compile(signature)
        except (ImportError, AttributeError, TypeError, numba.core.errors.NumbaError):
            continue
    return time.perf_counter() - started


def remember(kind: str) -> None:
    """Add the kernels this process called, with their signatures, to what runs of `kind` use
    (written whole, under a temporary name; nothing when the cache cannot be written)."""
    used = _manifest(kind)
    for name, dispatcher in DISPATCHERS.items():
        known = used.setdefault(name, [])
        known += [signature for signature in dispatcher.signatures if signature not in known]
    used = {name: signatures for name, signatures in used.items() if signatures}
    path = _manifest_path(kind)
    with contextlib.suppress(OSError, pickle.PicklingError):
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
        try:
            with os.fdopen(handle, "wb") as stream:
                pickle.dump(used, stream)
            os.replace(temporary, path)
        except BaseException:
            os.unlink(temporary)
            raise
