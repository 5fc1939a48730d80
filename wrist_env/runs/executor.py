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
    """Base: `submit` tasks, then iterate `results`; `close` when done (or use `with`).

    The subclasses are `Inline` (this process), `Processes` (spawned local processes) and `Dask` (a
    dask.distributed scheduler); `executor` picks one.

    Attributes
    ----------
    workers : int
        The processes tasks run on (1 for this process).
    threads : int or None
        Numba threads per local process (None: not set here).
    scheduler : str or None
        A dask.distributed scheduler's address, or None for local processes.
    inline : bool
        Whether tasks run in this process (a progress bar can then follow each batch).
    """

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
    """Tasks on `workers` spawned local processes with `threads` Numba threads each (default ⌊cores / workers⌋),
    started after `warm()`, if given, has run here (it compiles the kernels the tasks call: each worker then loads them
    from Numba's cache instead of compiling them)."""

    def __init__(self, workers: int, threads: int | None = None, warm: Callable[[], object] | None = None):
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        if warm is not None:
            warm()
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
    """Tasks on a dask.distributed scheduler (an address, or a `distributed.Client` the caller keeps).

    `results` raises `SchedulerError` (not a task's error: nothing can run) when the scheduler has had no
    worker for `no_workers_timeout_s` while tasks wait (it would otherwise wait for one forever, silently),
    or when it cancelled a task (it was stopped or restarted, or lost the task)."""

    def __init__(self, scheduler, no_workers_timeout_s: float | None = None):
        from distributed import Client

        self.own = not isinstance(scheduler, Client)
        self.client = _connect(scheduler) if self.own else scheduler
        self.scheduler = scheduler if isinstance(scheduler, str) else str(scheduler)
        self.no_workers_timeout_s = NO_WORKERS_TIMEOUT_S if no_workers_timeout_s is None else no_workers_timeout_s

    def submit(self, fn: Callable, *args: Any, **kwargs: Any) -> distributed.Future:
        return self.client.submit(fn, *args, pure=False, key=f"wrist-env-{os.getpid()}-{time.time_ns()}", **kwargs)

    def results(
        self, handles: Iterable[Any], on_poll: Callable[[], None] | None = None, poll_seconds: float = POLL_SECONDS
    ) -> Iterator[tuple[object, object, BaseException | None]]:
        from concurrent.futures import CancelledError  # distributed's FutureCancelledError is one

        watch = _NoWorkers(self, on_poll)
        for handle, value, error in super().results(handles, watch.poll, poll_seconds):
            if isinstance(error, CancelledError):
                raise SchedulerError(
                    f"the dask scheduler {self.scheduler} cancelled a task ({describe(error)[:200]}): it was "
                    "stopped or restarted, or lost the task's workers"
                ) from None
            watch.since = None  # a task finished: some worker is there
            yield handle, value, error

    def workers_count(self) -> int:
        """The workers the scheduler has now; `SchedulerError` if it does not answer."""
        try:
            return len(self.client.scheduler_info(n_workers=-1).get("workers", {}))
        except (OSError, TimeoutError) as e:  # distributed's CommClosedError is an OSError
            raise SchedulerError(
                f"the dask scheduler {self.scheduler} stopped answering ({describe(e)[:200]})"
            ) from None

    def close(self) -> None:
        if self.own:
            self.client.close()


class _NoWorkers:
    """`poll()`: the caller's `on_poll`, then `SchedulerError` once the scheduler of `dask` has had no worker
    for its `no_workers_timeout_s` (s, counted from the first poll that found none)."""

    def __init__(self, dask: Dask, on_poll: Callable[[], None] | None):
        self.dask, self.on_poll, self.since = dask, on_poll, None

    def poll(self) -> None:
        if self.on_poll is not None:
            self.on_poll()
        if self.dask.workers_count():
            self.since = None
            return
        now = time.monotonic()
        self.since = now if self.since is None else self.since
        waited_s = now - self.since
        if waited_s >= self.dask.no_workers_timeout_s:
            address = self.dask.scheduler
            raise SchedulerError(
                f"the dask scheduler {address} has had no workers for {round(waited_s, 1):g} s, so no task can run; "
                f"start one with `dask worker {address}` (on a machine that sees this folder and has wrist-env)"
            )


CONNECT_TIMEOUT_S = 30.0
"""How long to wait for a dask scheduler to answer (s)."""
NO_WORKERS_TIMEOUT_S = 60.0
"""How long tasks wait on a dask scheduler that has no worker before `Dask.results` gives up (s)."""
SCHEMES = ("tcp", "ws", "tls", "wss", "inproc")
"""Address schemes of a dask scheduler this client can reach: tls and wss only with a client certificate
configured in dask's `distributed.comm.tls` settings (`_check_address`)."""


class SchedulerError(WristEnvError, ConnectionError):
    """A dask scheduler that cannot be reached, has no worker, or dropped the tasks."""


def _check_address(address: str) -> None:
    """`SchedulerError` naming `address` unless it is one this client can reach (`SCHEMES`): a scheme
    without a transport here, or TLS without the certificates it needs, in one line instead of
    distributed's traceback."""
    if not address.strip():
        raise SchedulerError("the dask scheduler address is empty; give one such as tcp://host:8786")
    scheme = address.split("://", 1)[0].lower() if "://" in address else "tcp"
    if scheme not in SCHEMES:
        raise SchedulerError(
            f"the dask scheduler address {address!r} has the scheme {scheme!r}, which this client cannot use; "
            f"give a {', '.join(s + '://' for s in SCHEMES if s != 'inproc')} address (e.g. tcp://host:8786)"
        )
    if scheme in ("tls", "wss"):
        from distributed.security import Security

        if Security().get_connection_args("client").get("ssl_context") is None:
            raise SchedulerError(
                f"the dask scheduler address {address!r} is TLS, but dask has no client certificate configured: "
                "set distributed.comm.tls.ca-file, .client.cert and .client.key in dask's configuration "
                "(https://distributed.dask.org/en/stable/tls.html), or use the scheduler's tcp:// address"
            )


def _connect(address: str) -> distributed.Client:
    """A client of the scheduler at `address` (`_check_address` first); `SchedulerError` naming it if it
    does not answer within `CONNECT_TIMEOUT_S`."""
    from distributed import Client

    _check_address(address)
    timeout_s = CONNECT_TIMEOUT_S
    try:
        return Client(address, timeout=f"{timeout_s}s")
    except (OSError, TimeoutError, ValueError, TypeError) as e:  # TypeError: distributed's, on a TLS misconfiguration
        raise SchedulerError(
            f"cannot reach the dask scheduler {address!r} within {timeout_s:g} s ({type(e).__name__}: "
            f"{str(e).splitlines()[0][:200] if str(e) else 'no answer'}); is it running, and is the address right?"
        ) from None


def executor(
    scheduler: str | distributed.Client | None = None,
    workers: int = 0,
    threads: int | None = None,
    warm: Callable[[], object] | None = None,
) -> Executor:
    """Dask if `scheduler` is given, else `workers` local processes (≥ 2), else this process.

    Parameters
    ----------
    scheduler : str or distributed.Client, optional
        A dask.distributed scheduler's address, or a client the caller keeps.
    workers : int, default 0
        Local worker processes; 0 or 1 run the tasks in this process.
    threads : int, optional
        Numba threads per local process (default ⌊cores / workers⌋ for processes).
    warm : callable, optional
        Called once, with no arguments, before local processes start: what compiles the kernels their tasks
        call (`participants.registry.warm_solver`), so that each loads them from Numba's cache instead of
        compiling them. Not called for dask or this process.

    Returns
    -------
    Executor
        `Dask`, `Processes` or `Inline`; use it with ``with`` so that it is closed.

    Examples
    --------
    >>> from wrist_env.runs import executor
    >>> with executor(workers=0) as ex:
    ...     handles = [ex.submit(pow, 2, k) for k in range(3)]
    ...     sorted(value for _, value, _ in ex.results(handles))
    [1, 2, 4]
    """
    if scheduler is not None:
        return Dask(scheduler)
    if workers and int(workers) > 1:
        return Processes(int(workers), threads, warm)
    return Inline(threads)
