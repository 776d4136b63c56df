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
from typing import Any, Generic, TypeVar

from vplane_mj.bench.failures import call_or_failure, worker_died
from vplane_mj.sim.failure import RunFailure

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
    pool = _Workers[Item](run, workers)
    finished_normally = False
    try:
        while queue or pool.busy:
            pool.hand_out(queue)
            results = pool.collect()
            pool.hand_out(queue)  # before the caller takes its time over the results
            yield from results
        finished_normally = True
    finally:
        pool.stop(at_once=not finished_normally)


class _Workers(Generic[Item]):
    """The worker processes: idle ones, busy ones with their items, and every one started and
    not yet reaped (registered before it starts, so that an interruption, which may come
    between any two steps here, still finds it)."""

    def __init__(self, run: Callable[[Item], Any], size: int):
        self._run = partial(call_or_failure, run)
        self._size = size
        self._started: list[_Worker] = []
        self.idle: list[_Worker] = []
        self.busy: dict[_Worker, Item] = {}

    def hand_out(self, queue: deque[Item]) -> None:
        """Give queued items to idle workers, starting new ones, until `size` are busy."""
        while queue and len(self.busy) < self._size:
            worker = self.idle.pop() if self.idle else self._start()
            item = queue.popleft()
            try:
                worker.connection.send(item)
            except OSError:  # the worker died while idle: the item waits for the next one
                queue.appendleft(item)
                self._reap(worker)
                continue
            self.busy[worker] = item

    def collect(self) -> list[tuple[Item, Any]]:
        """Wait until busy workers answer or die; their items with the results or failures.

        Workers that answered become idle; dead ones are reaped.
        """
        busy = self.busy
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
                result = worker_died(self._reap(worker))
            else:
                self.idle.append(worker)
            results.append((item, result))
        return results

    def stop(self, at_once: bool) -> None:
        """End every worker: at once (SIGTERM), or by sending idle ones None (closing our end
        of their pipes would not do: workers forked later hold copies of it)."""
        started = [worker for worker in self._started if worker.process.pid is not None]
        for worker in started:
            if at_once:
                worker.process.terminate()
            else:
                with contextlib.suppress(OSError):
                    worker.connection.send(None)
        for worker in started:
            self._reap(worker)

    def _start(self) -> _Worker:
        ours, theirs = multiprocessing.Pipe()
        process = multiprocessing.Process(target=_serve, args=(theirs, self._run, os.getpid()))
        worker = _Worker(process, ours)
        self._started.append(worker)
        process.start()
        theirs.close()  # the worker holds the only copy: its death ends our end of the pipe
        return worker

    def _reap(self, worker: _Worker) -> int:
        """Wait for a worker that is ending (terminate it if it does not); its exit code."""
        worker.process.join(JOIN_TIMEOUT_S)
        if worker.process.is_alive():
            worker.process.terminate()
            worker.process.join()
        worker.connection.close()
        self._started.remove(worker)
        exit_code = worker.process.exitcode
        assert exit_code is not None, "a joined process has an exit code"
        return exit_code


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
