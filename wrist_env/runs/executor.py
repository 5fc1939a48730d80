"""Where a study's tasks run: this process, local worker processes, or a dask.distributed cluster.

One interface for the benchmark (a task = one calibration cell, which logs as
it goes) and the Monte Carlo study (a task = one chunk of runs, which this
process logs): `submit(fn, *args, **kwargs)` returns a handle, `results(handles)`
yields `(handle, value, error)` as tasks finish — a task's exception is handed
back, never raised, so one failure does not stop the others.

Local workers are spawned (no fork after Numba's threads started) after this process has compiled the
kernel (`simulate.warm`: they load it from Numba's cache instead of each compiling it), run with
⌊cores / workers⌋ Numba threads each, and die with their parent: a killed
study leaves no process computing or logging (Linux: PR_SET_PDEATHSIG; the
worker also exits at start if its parent is already gone).
"""

from __future__ import annotations

import os
import sys
import time
import traceback
from collections.abc import Callable, Iterable, Iterator
from typing import TYPE_CHECKING, Any

from wrist_env.errors import WristEnvError

if TYPE_CHECKING:
    from concurrent.futures import Future

    import distributed

POLL_SECONDS = 0.5


def set_threads(threads: int | None) -> None:
    """Limit Numba's parallel threads in this process (None: leave as is)."""
    if threads is None:
        return
    import numba

    numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))


def _init_worker(threads: int | None, parent: int) -> None:
    """A local worker: die with the parent, then set its Numba threads."""
    if sys.platform.startswith("linux"):
        import ctypes
        import signal

        try:
            ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
        except OSError:
            pass
    if os.getppid() != parent:
        os._exit(1)
    set_threads(threads)


def describe(error: BaseException) -> str:
    """One line naming an exception's type and message."""
    return "".join(traceback.format_exception_only(type(error), error)).strip()


class Executor:
    """Base: `submit` tasks, then iterate `results`; `close` when done (or use `with`)."""

    workers: int = 1
    threads: int | None = None
    scheduler: str | None = None
    inline: bool = False

    def submit(self, fn: Callable, *args: Any, **kwargs: Any) -> Any:
        raise NotImplementedError

    def results(
        self, handles: Iterable[Any], on_poll: Callable[[], None] | None = None, poll_seconds: float = POLL_SECONDS
    ) -> Iterator[tuple[object, object, BaseException | None]]:
        """(handle, value, error) for every handle, as each finishes; `on_poll()` every `poll_seconds`."""
        pending = list(handles)
        while pending:
            done = [h for h in pending if h.done()]
            for h in done:
                pending.remove(h)
                try:
                    yield h, h.result(), None
                except Exception as e:  # noqa: BLE001  (handed to the caller)
                    yield h, None, e
            if on_poll is not None:
                on_poll()
            if pending and not done:
                time.sleep(poll_seconds)

    def close(self) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class _Task:
    def __init__(self, fn, args, kwargs):
        self.fn, self.args, self.kwargs = fn, args, kwargs


class Inline(Executor):
    """Tasks in this process, one at a time, when `results` reaches them (Numba may use every core)."""

    inline = True

    def __init__(self, threads: int | None = None):
        self.threads = threads
        set_threads(threads)

    def submit(self, fn: Callable, *args: Any, **kwargs: Any) -> _Task:
        return _Task(fn, args, kwargs)

    def results(
        self, handles: Iterable[Any], on_poll: Callable[[], None] | None = None, poll_seconds: float = POLL_SECONDS
    ) -> Iterator[tuple[object, object, BaseException | None]]:
        for task in handles:
            try:
                value, error = task.fn(*task.args, **task.kwargs), None
            except Exception as e:  # noqa: BLE001
                value, error = None, e
            yield task, value, error
            if on_poll is not None:
                on_poll()


class Processes(Executor):
    """Tasks on `workers` spawned local processes with `threads` Numba threads each (default ⌊cores / workers⌋)."""

    def __init__(self, workers: int, threads: int | None = None):
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        from wrist_env.solver.simulate import warm

        warm()  # compile once here; the workers load it from Numba's cache instead of each compiling it
        self.workers = max(1, int(workers))
        self.threads = threads if threads is not None else max(1, (os.cpu_count() or 1) // self.workers)
        self.pool = ProcessPoolExecutor(
            self.workers,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_init_worker,
            initargs=(self.threads, os.getpid()),
        )

    def submit(self, fn: Callable, *args: Any, **kwargs: Any) -> Future:
        return self.pool.submit(fn, *args, **kwargs)

    def close(self) -> None:
        self.pool.shutdown(cancel_futures=True)


class Dask(Executor):
    """Tasks on a dask.distributed scheduler (an address, or a `distributed.Client` the caller keeps)."""

    def __init__(self, scheduler):
        from distributed import Client

        self.own = not isinstance(scheduler, Client)
        self.client = _connect(scheduler) if self.own else scheduler
        self.scheduler = scheduler if isinstance(scheduler, str) else str(scheduler)

    def submit(self, fn: Callable, *args: Any, **kwargs: Any) -> distributed.Future:
        return self.client.submit(fn, *args, pure=False, key=f"wrist-env-{os.getpid()}-{time.time_ns()}", **kwargs)

    def close(self) -> None:
        if self.own:
            self.client.close()


CONNECT_TIMEOUT_S = 30.0
"""How long to wait for a dask scheduler to answer (s)."""


class SchedulerError(WristEnvError, ConnectionError):
    """A dask scheduler that cannot be reached."""


def _connect(address: str) -> distributed.Client:
    """A client of the scheduler at `address`; `SchedulerError` naming it if it does not answer
    within `CONNECT_TIMEOUT_S`."""
    from distributed import Client

    timeout_s = CONNECT_TIMEOUT_S
    try:
        return Client(address, timeout=f"{timeout_s}s")
    except (OSError, TimeoutError, ValueError) as e:
        raise SchedulerError(
            f"cannot reach the dask scheduler {address!r} within {timeout_s:g} s ({type(e).__name__}: "
            f"{str(e).splitlines()[0][:200] if str(e) else 'no answer'}); is it running, and is the address right?"
        ) from None


def executor(
    scheduler: str | distributed.Client | None = None, workers: int = 0, threads: int | None = None
) -> Executor:
    """Dask if `scheduler` is given, else `workers` local processes (≥ 2), else this process."""
    if scheduler is not None:
        return Dask(scheduler)
    if workers and int(workers) > 1:
        return Processes(int(workers), threads)
    return Inline(threads)
