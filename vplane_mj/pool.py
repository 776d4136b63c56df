"""The local process pool of a sweep, which outlives its workers.

Each worker process runs one item at a time, sent to it over its own pipe, and sends back
what `run` returned, or a RunFailure when it raised. A worker that dies (killed by the OOM
killer or another signal, a crash in native code) fails only the item it had under way, with
a RunFailure that names the signal or the exit status; a new process takes its place and
the queued items go on. Closing the iteration early (an interruption, an error in the
caller) terminates every worker at once.

Workers ignore SIGINT, which Ctrl-C sends to the whole process group, and leave it to the
sweep; a worker whose sweep was killed outright exits by itself.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import threading
import time
from collections import deque
from collections.abc import Callable, Generator, Iterable
from dataclasses import dataclass
from functools import partial
from multiprocessing.connection import Connection, wait
from multiprocessing.process import BaseProcess
from typing import Any, TypeVar

from vplane_mj.failures import RunFailure, call_or_failure, worker_died

Item = TypeVar("Item")
Result = TypeVar("Result")

JOIN_TIMEOUT_S = 5.0
"""How long a worker that closed its pipe or was told to stop may take to exit (s)."""
ORPHAN_POLL_S = 0.5
"""How often a worker checks that the sweep that started it is still its parent (s)."""


@dataclass(eq=False)
class _Worker:
    """A worker process and the sweep's end of its pipe."""

    process: BaseProcess
    connection: Connection


def run_in_pool(
    items: Iterable[Item], run: Callable[[Item], Result], workers: int
) -> Generator[tuple[Item, Result | RunFailure], None, None]:
    """Each item with what `run(item)` gave in one of `workers` processes, as they finish.

    `run` must be picklable (a module-level function). However the iteration ends, no
    worker is left running.
    """
    queue = deque(items)
    idle: list[_Worker] = []
    busy: dict[_Worker, Item] = {}
    finished_normally = False
    try:
        while queue or busy:
            _hand_out(queue, idle, busy, workers, run)
            results = _collect(busy, idle)
            _hand_out(queue, idle, busy, workers, run)  # before the caller takes its time
            yield from results
        finished_normally = True
    finally:
        _stop([*idle, *busy], at_once=not finished_normally)


def _hand_out(
    queue: deque[Item],
    idle: list[_Worker],
    busy: dict[_Worker, Item],
    workers: int,
    run: Callable[[Item], Any],
) -> None:
    """Give queued items to idle workers, starting new ones, until `workers` are busy."""
    while queue and len(busy) < workers:
        worker = idle.pop() if idle else _start_worker(run)
        item = queue.popleft()
        try:
            worker.connection.send(item)
        except OSError:  # the worker died while idle: the item waits for the next one
            queue.appendleft(item)
            _reap(worker)
            continue
        busy[worker] = item


def _collect(busy: dict[_Worker, Item], idle: list[_Worker]) -> list[tuple[Item, Any]]:
    """Wait until busy workers answer or die; their items with the results or failures.

    Workers that answered become idle; dead ones are reaped.
    """
    ready = set(wait([w.connection for w in busy] + [w.process.sentinel for w in busy]))
    results: list[tuple[Item, Any]] = []
    for worker in [w for w in busy if w.connection in ready or w.process.sentinel in ready]:
        item = busy.pop(worker)
        try:
            # A worker that died is readable too (end of file), and may have answered first.
            if not worker.connection.poll():
                raise EOFError
            result = worker.connection.recv()
        except (EOFError, OSError):
            result = worker_died(_reap(worker))
        else:
            idle.append(worker)
        results.append((item, result))
    return results


def _start_worker(run: Callable[[Any], Any]) -> _Worker:
    ours, theirs = multiprocessing.Pipe()
    guarded = partial(call_or_failure, run)
    process = multiprocessing.Process(target=_serve, args=(theirs, guarded, os.getpid()))
    process.start()
    theirs.close()  # the worker holds the only copy: its death ends our end of the pipe
    return _Worker(process, ours)


def _reap(worker: _Worker) -> int | None:
    """Wait for a worker that is ending (terminate it if it does not); its exit code."""
    worker.process.join(JOIN_TIMEOUT_S)
    if worker.process.is_alive():
        worker.process.terminate()
        worker.process.join()
    worker.connection.close()
    return worker.process.exitcode


def _stop(workers: list[_Worker], at_once: bool) -> None:
    """End the workers: at once (SIGTERM), or by sending idle ones None (closing our end of
    their pipes would not do: workers forked later hold copies of it)."""
    for worker in workers:
        if at_once:
            worker.process.terminate()
        else:
            with contextlib.suppress(OSError):
                worker.connection.send(None)
    for worker in workers:
        _reap(worker)


def _serve(connection: Connection, run: Callable[[Any], Any], sweep_pid: int) -> None:
    """A worker process: run the items that come through the pipe and send back what `run`
    gives, until None comes (or the pipe ends)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    threading.Thread(target=_exit_when_orphaned, args=(sweep_pid,), daemon=True).start()
    while True:
        try:
            item = connection.recv()
        except EOFError:
            return
        if item is None:
            return
        connection.send(run(item))


def _exit_when_orphaned(sweep_pid: int) -> None:
    """In a worker: exit as soon as its parent is no longer the sweep that started it."""
    while os.getppid() == sweep_pid:
        time.sleep(ORPHAN_POLL_S)
    os._exit(1)
