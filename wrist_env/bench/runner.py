"""The benchmark runner: participants × calibrators × seeds, one cell each, logged and resumable.

Cells run on local processes (the default) or on a `dask.distributed`
scheduler given by address, one task per cell. Every cell writes its batches
to the run log in `out_dir` as they finish (`wrist_env.bench.log`); a cell
already finished is skipped, one cut short resumes by replay. Workers must
see `out_dir` (same machine, or a shared file system).

Local processes: `workers` processes (default: one per core), each with
⌊cores / workers⌋ Numba threads for the batched solver. On this 2-core
machine two single-threaded processes beat one process with two threads:
calibrators that ask one point at a time (Nelder–Mead, a TPE step, the
surrogate's search) cannot fill two threads, and a batch's slowest design
holds the other thread idle (README, "Benchmark", has the measurement).
"""

from __future__ import annotations

import itertools
import os
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

from wrist_env.bench.log import RunKey, RunLog

POLL_SECONDS = 0.5


@dataclass
class BenchmarkReport:
    """What a `benchmark` call did: cells run, skipped (already finished) and failed (with the error)."""

    out_dir: Path
    cells: list[RunKey]
    ran: list[RunKey] = field(default_factory=list)
    skipped: list[RunKey] = field(default_factory=list)
    failed: list[tuple[RunKey, str]] = field(default_factory=list)
    wall_seconds: float = 0.0
    workers: int = 1
    threads: int | None = None
    scheduler: str | None = None

    @property
    def evaluations(self) -> int:
        return sum(RunLog(self.out_dir).progress().get(k.name, 0) for k in self.cells)


def make_cells(participants, optimizers, seeds, budget: int) -> list[RunKey]:
    """The cross product participants × optimizers × seeds (seeds: a count n → 0 … n−1, or a list)."""
    seeds = list(range(seeds)) if isinstance(seeds, int) else [int(s) for s in seeds]
    if budget < 1 or not seeds or not participants or not optimizers:
        raise ValueError("a benchmark needs ≥ 1 participant, optimizer and seed, and a budget ≥ 1")
    return [RunKey(p, o, s, int(budget)) for p, o, s in itertools.product(participants, optimizers, seeds)]


NO_STORAGE = ("memory", "none")
"""Storage values that keep Optuna studies in memory (faster; the Parquet log is still the record)."""
STORAGE_PER_CELL = "{cell}"
"""Placeholder in a storage URL, replaced by the cell's key name (one database per cell)."""


def default_storage(out_dir) -> str:
    """The Optuna storage of a run directory: a SQLite file per cell, `optuna/<cell>.db`, whose study is
    named by the cell's key. (One file shared by parallel workers made Optuna cells 2× slower: SQLite's
    writers wait on each other's locks.)"""
    return f"sqlite:///{Path(out_dir).resolve() / 'optuna' / STORAGE_PER_CELL}.db"


def cell_storage(storage: str | None, key: RunKey) -> str | None:
    """The storage URL of one cell (`{cell}` replaced by its key name; SQLite folders created)."""
    if storage is None or STORAGE_PER_CELL not in storage:
        return storage
    url = storage.replace(STORAGE_PER_CELL, key.name)
    if url.startswith("sqlite:///"):
        Path(url[len("sqlite:///"):]).parent.mkdir(parents=True, exist_ok=True)
    return url


def set_threads(threads: int | None) -> None:
    """Limit Numba's parallel threads in this process (None: leave as is)."""
    if threads is None:
        return
    import numba

    numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))


def run_cell(key: RunKey, out_dir: str, storage: str | None = None, options: dict | None = None,
             threads: int | None = None, folders: tuple = (), callback=None) -> dict:
    """Run (or resume, or skip) one cell; returns {"status": "ran" | "skipped", "summary": {...}}.

    The top-level function a local process or a dask worker runs. It holds the
    cell's lock meanwhile, so a leftover process of a killed run and its
    restart never run the same cell at once.
    """
    from wrist_env.bench.calibrate import calibrate
    from wrist_env.participants import registry

    set_threads(threads)
    for folder in folders:
        registry.add_folder(folder)
    log = RunLog(out_dir)
    with log.lock(key):
        summary = log.summary(key)
        if summary is not None:
            return {"status": "skipped", "summary": summary}
        run = calibrate(key.participant, key.optimizer, key.budget, key.seed, log=log,
                        storage=cell_storage(storage, key),
                        options=(options or {}).get(key.optimizer), callback=callback)
        return {"status": "ran", "summary": run.to_dict()}


def _init_worker(threads: int | None, parent: int) -> None:
    """Local worker process: die with the parent (a killed run leaves no process logging), set threads."""
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


def benchmark(participants, optimizers, seeds, budget: int, out_dir, *, workers: int | None = None,
              scheduler=None, progress: bool = True, storage: str | None = None, threads: int | None = None,
              options: dict | None = None, folders=()) -> BenchmarkReport:
    """Run every cell of participants × optimizers × seeds with `budget` evaluations into `out_dir`.

    workers: local processes (default: the number of cores; 1 runs the cells in this process).
    threads: Numba threads per local process (default ⌊cores / workers⌋).
    scheduler: a dask.distributed scheduler address (or a `distributed.Client`): one task per cell.
    storage: Optuna storage URL for calibrators that take one, "{cell}" replaced by the cell's key name
        (default: `sqlite:///<out_dir>/optuna/{cell}.db`); the study is named by the cell's key.
        "memory": studies in memory only (Optuna cells ~2× faster; resume still works, by replay).
    options: {optimizer name: {option: value}} passed to `optimizers.make`.
    folders: participant folders to register (in every worker too).
    """
    start = time.perf_counter()
    out_dir = Path(out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    cells = make_cells(participants, optimizers, seeds, budget)
    _check_names(cells, folders)
    if storage is None:
        storage = default_storage(out_dir)
    elif storage in NO_STORAGE:
        storage = None
    _prepare_storage(cells, storage)
    log = RunLog(out_dir)
    done = {k for k in cells if log.summary(k) is not None}
    report = BenchmarkReport(out_dir, cells, skipped=[k for k in cells if k in done])
    todo = [k for k in cells if k not in done]
    cores = os.cpu_count() or 1
    total = sum(k.budget for k in cells)
    bar = _bar(progress, total, sum(min(log.progress().get(k.name, 0), k.budget) for k in cells), len(cells), len(done))
    try:
        if scheduler is not None:
            report.scheduler = scheduler if isinstance(scheduler, str) else str(scheduler)
            _run_dask(todo, scheduler, out_dir, storage, options, tuple(str(f) for f in folders), report, bar, log)
        else:
            workers = max(1, min(int(workers or cores), max(1, len(todo))))
            threads = threads if threads is not None else max(1, cores // workers)
            report.workers, report.threads = workers, threads
            if workers == 1:
                _run_here(todo, out_dir, storage, options, threads, tuple(str(f) for f in folders), report, bar)
            else:
                _run_processes(todo, workers, threads, out_dir, storage, options, tuple(str(f) for f in folders),
                               report, bar, log)
    finally:
        if bar is not None:
            bar.close()
    report.wall_seconds = time.perf_counter() - start
    return report


def _check_names(cells, folders) -> None:
    import optimizers
    from wrist_env.errors import ParticipantError
    from wrist_env.participants import registry

    for folder in folders:
        registry.add_folder(folder)
    known = registry.participants()
    for name in sorted({k.participant for k in cells}):
        if name not in known:
            raise ParticipantError(f"unknown participant {name!r}; known: {list(known)}")
    for name in sorted({k.optimizer for k in cells}):
        optimizers.get(name)  # UnknownOptimizerError lists the registered ones


def _prepare_storage(cells, storage) -> None:
    """Create the Optuna storage's tables once, before parallel workers open it."""
    import optimizers
    from wrist_env.bench.calibrate import accepts_storage, open_storage

    if isinstance(storage, str) and STORAGE_PER_CELL not in storage and \
            any(accepts_storage(optimizers.get(name)) for name in {k.optimizer for k in cells}):
        open_storage(storage)


def _bar(progress, total, initial, n_cells, n_done):
    if not progress:
        return None
    from tqdm import tqdm

    bar = tqdm(total=total, initial=initial, unit="eval", desc="benchmark", dynamic_ncols=True, smoothing=0.05,
               mininterval=1.0)
    bar.set_postfix_str(f"cells {n_done}/{n_cells}", refresh=False)
    return bar


def _update(bar, log: RunLog, cells, report) -> None:
    if bar is None:
        return
    progress = log.progress()
    n = sum(min(progress.get(k.name, 0), k.budget) for k in cells)
    if n > bar.n:
        bar.update(n - bar.n)
    bar.set_postfix_str(f"cells {len(report.ran) + len(report.skipped)}/{len(cells)}"
                        + (f", {len(report.failed)} failed" if report.failed else ""), refresh=False)


def _collect(report: BenchmarkReport, key: RunKey, future) -> None:
    try:
        out = future.result()
    except Exception as exc:  # noqa: BLE001  (a failed cell must not stop the others)
        detail = "".join(traceback.format_exception_only(type(exc), exc)).strip()
        report.failed.append((key, detail))
        return
    (report.skipped if out["status"] == "skipped" else report.ran).append(key)


def _run_here(todo, out_dir, storage, options, threads, folders, report, bar) -> None:
    for key in todo:
        def tick(n_new, nfev):
            if bar is not None and n_new:
                bar.update(n_new)
        try:
            out = run_cell(key, out_dir, storage, options, threads, folders, callback=tick)
        except Exception as exc:  # noqa: BLE001  (a failed cell must not stop the others)
            report.failed.append((key, "".join(traceback.format_exception_only(type(exc), exc)).strip()))
            continue
        (report.skipped if out["status"] == "skipped" else report.ran).append(key)
        if bar is not None:
            bar.set_postfix_str(f"cells {len(report.ran) + len(report.skipped)}/{len(report.cells)}", refresh=False)


def _run_processes(todo, workers, threads, out_dir, storage, options, folders, report, bar, log) -> None:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    context = multiprocessing.get_context("spawn")  # no fork after Numba's threads started
    with ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=_init_worker,
                             initargs=(threads, os.getpid())) as pool:
        futures = {pool.submit(run_cell, key, str(out_dir), storage, options, None, folders): key for key in todo}
        _wait(futures, report, bar, log)


def _run_dask(todo, scheduler, out_dir, storage, options, folders, report, bar, log) -> None:
    from distributed import Client

    client = Client(scheduler) if isinstance(scheduler, str) else scheduler
    try:
        futures = {client.submit(run_cell, key, str(out_dir), storage, options, None, folders, pure=False,
                                 key=f"wrist-bench-{key.name}-{os.getpid()}-{time.time_ns()}"): key for key in todo}
        _wait(futures, report, bar, log)
    finally:
        if isinstance(scheduler, str):
            client.close()


def _wait(futures: dict, report, bar, log) -> None:
    pending = dict(futures)
    while pending:
        for future in [f for f in pending if f.done()]:
            _collect(report, pending.pop(future), future)
        _update(bar, log, report.cells, report)
        if pending:
            time.sleep(POLL_SECONDS)
    _update(bar, log, report.cells, report)
