"""The benchmark runner: participants × instances × calibrators × seeds, one cell each, logged and resumable.

A cell is (participant, instance, calibrator, seed) at a budget (`RunKey`). An instance is a problem
of a built-in participant (`participants.instances`: instance 0 its shipped truth and trials, k ≥ 1 a
truth drawn from the prior with the trials made from it). As in COCO's experiments, a run on instance
k is seeded with k unless seeds are given (`make_cells`'s `seeds=SEED_IS_INSTANCE`): the benchmark
over instances 1 … 5 is five runs per participant and calibrator, each on its own problem and seed.
Explicit seeds cross every instance (n seeds on each).

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
holds the other thread idle (docs/history.md, "The benchmark", has the measurement).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import optimizers
from optimizers.optuna_storage import open_url
from wrist_env.bench.calibrate import accepts_storage, calibrate, split_prior
from wrist_env.bench.cells import make_cells
from wrist_env.bench.log import RunLog
from wrist_env.bench.schema import RunKey
from wrist_env.errors import ParticipantError
from wrist_env.limits import MAX_THREADS, MAX_WORKERS, check_int
from wrist_env.participants import builtin, registry
from wrist_env.runs import provenance
from wrist_env.runs.executor import describe, executor, set_threads

if TYPE_CHECKING:
    from distributed import Client


@dataclass
class BenchmarkReport:
    """What a `benchmark` call did: cells run, skipped (already finished) and failed (with the error).

    Parameters
    ----------
    out_dir : Path
        The run log's folder (resolved).
    cells : list of RunKey, length n_cells
        Every cell asked for.
    ran : list of RunKey
        The cells run (or resumed) to their end by this call.
    skipped : list of RunKey
        The cells finished before this call, or found finished by their worker.
    failed : list of (RunKey, str)
        The cells that raised, each with its error described in one line.
    wall_seconds : float
        Wall time of the call, s.
    workers : int, default 1
        The local processes the executor ran.
    threads : int or None
        Numba threads per local process (None: not set by the executor).
    scheduler : str or None
        The dask.distributed scheduler's address, or None for local processes.

    Attributes
    ----------
    evaluations : int
        Evaluations the run log holds for these cells (read from the log when asked).
    """

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


NO_STORAGE = ("memory", "none")
"""Storage values that keep Optuna studies in memory (faster; the Parquet log is still the record)."""
STORAGE_PER_CELL = "{cell}"
"""Placeholder in a storage URL, replaced by the cell's key name (one database per cell)."""


def default_storage(out_dir: str | Path) -> str:
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
        Path(url[len("sqlite:///") :]).parent.mkdir(parents=True, exist_ok=True)
    return url


def run_cell(
    key: RunKey,
    out_dir: str,
    storage: str | None = None,
    options: dict | None = None,
    threads: int | None = None,
    folders: tuple = (),
    callback: Callable[[int, int], object] | None = None,
) -> dict:
    """Run (or resume, or skip) one cell; returns {"status": "ran" | "skipped", "summary": {...}}.

    The top-level function a local process or a dask worker runs. It holds the
    cell's lock meanwhile, so a leftover process of a killed run and its
    restart never run the same cell at once.
    """

    set_threads(threads)
    for folder in folders:
        registry.ensure_folder(folder)
    log = RunLog(out_dir)
    with log.lock(key):
        made_from = provenance.of_participant(key.participant, key.instance)
        log.move_aside_stale(key, made_from)
        summary = log.summary(key)
        if summary is not None:
            return {"status": "skipped", "summary": summary}
        run = calibrate(
            key.participant,
            key.optimizer,
            key.budget,
            key.seed,
            log=log,
            storage=cell_storage(storage, key),
            options=(options or {}).get(key.optimizer, (options or {}).get(split_prior(key.optimizer)[0])),
            callback=callback,
            made_from=made_from,
            instance=key.instance,
        )
        return {"status": "ran", "summary": run.to_dict()}


def benchmark(
    participants: Sequence[str],
    optimizers: Sequence[str],
    seeds: int | Iterable[int] | str,
    budget: int,
    out_dir: str | Path,
    *,
    instances: int | Iterable[int] | None = None,
    workers: int | None = None,
    scheduler: str | Client | None = None,
    progress: bool = True,
    storage: str | None = None,
    threads: int | None = None,
    options: dict | None = None,
    folders: Sequence[str | Path] = (),
) -> BenchmarkReport:
    """Run the calibration benchmark: every cell of participants × instances × optimizers × seeds.

    Each cell is one `calibrate` call with `budget` evaluations, logged batch by batch into the run log
    in `out_dir` (`RunLog`), so a benchmark stopped at any point resumes where it stopped: finished
    cells are skipped and a cell cut short is replayed. ``wrist-bench leaderboard`` (`write_leaderboard`)
    makes the tables and figures from the log.

    Parameters
    ----------
    participants : sequence of str
        Registered participant names.
    optimizers : sequence of str
        Calibrator names (`optimizers.available()`, optionally with ``+prior``).
    seeds : int, sequence of int or "instance"
        As `make_cells` takes them: a count, a list, or `SEED_IS_INSTANCE` (one run per instance, seeded
        with it).
    budget : int
        Evaluations per cell.
    out_dir : path
        The run log's folder (made if missing).
    instances : int, sequence of int or None, default None
        As `make_cells` takes them (None: instance 0 alone).
    workers : int, optional
        Local processes (default: the number of cores; 1 runs the cells in this process).
    scheduler : str or distributed.Client, optional
        A dask.distributed scheduler's address or client: one task per cell.
    progress : bool, default True
        A progress bar of evaluations.
    storage : str, optional
        An Optuna storage URL for calibrators that take one, "{cell}" replaced by the cell's key name
        (default ``sqlite:///<out_dir>/optuna/{cell}.db``); "memory": studies in memory only (resume
        still works, by replay).
    threads : int, optional
        Numba threads per local process (default ⌊cores / workers⌋).
    options : dict, optional
        ``{optimizer name: {option: value}}`` passed to `optimizers.make` (a ``+prior`` name takes its
        base calibrator's options unless given its own).
    folders : sequence of path, default ()
        Participant folders to register, in every worker too.

    Returns
    -------
    BenchmarkReport
        The cells run, skipped (finished before) and failed (with the error), and the wall time.

    Raises
    ------
    InputError
        Bad cells (`make_cells`) or a count of workers or threads out of bounds.
    ParticipantError
        An unknown participant, or an instance k ≥ 1 of a folder participant.
    UnknownOptimizerError
        An unregistered calibrator (the message lists the registered ones).

    Examples
    --------
    >>> from wrist_env.bench import RunLog, benchmark
    >>> report = benchmark(["P1"], ["random", "cmaes"], seeds=1, budget=16, out_dir="runs/tiny", workers=1)
    >>> RunLog("runs/tiny").read().groupby("optimizer").cost.min()  # doctest: +SKIP
    """
    start = time.perf_counter()
    cells = make_cells(participants, optimizers, seeds, budget, instances)
    if workers is not None:
        check_int("workers", workers, 1, MAX_WORKERS)
    if threads is not None:
        check_int("threads", threads, 1, MAX_THREADS)
    out_dir = Path(out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    _check_names(cells, folders)
    if storage is None:
        storage = default_storage(out_dir)
    elif storage in NO_STORAGE:
        storage = None
    _prepare_storage(cells, storage)
    log = RunLog(out_dir)
    log.repair()
    made_from: dict[tuple[str, int], dict] = {}  # loaded only for problems with something logged (no build here)
    for k in (k for k in cells if log.logged(k)):  # a cell made on another model or trials runs again
        if (k.participant, k.instance) not in made_from:
            made_from[k.participant, k.instance] = provenance.of_participant(k.participant, k.instance)
        log.move_aside_stale(k, made_from[k.participant, k.instance])
    done = {k for k in cells if log.summary(k) is not None}
    report = BenchmarkReport(out_dir, cells, skipped=[k for k in cells if k in done])
    todo = [k for k in cells if k not in done]
    cores = os.cpu_count() or 1
    if scheduler is None:
        workers = max(1, min(cores if workers is None else workers, len(todo)))
        threads = threads if threads is not None else max(1, cores // workers)
    total = sum(k.budget for k in cells)
    bar = _bar(progress, total, sum(min(log.progress().get(k.name, 0), k.budget) for k in cells), len(cells), len(done))
    folders = tuple(str(f) for f in folders)
    try:
        with executor(scheduler, workers, threads, warm=registry.warm_solver) as ex:
            report.workers, report.threads, report.scheduler = ex.workers, ex.threads, ex.scheduler
            handles = {}
            for key in todo:
                tick = _tick(bar) if ex.inline else None  # out of process, the bar follows the log
                handles[ex.submit(run_cell, key, str(out_dir), storage, options, None, folders, callback=tick)] = key
            for handle, out, error in ex.results(list(handles), on_poll=lambda: _update(bar, log, cells, report)):
                key = handles[handle]
                if error is not None:
                    report.failed.append((key, describe(error)))
                else:
                    (report.skipped if out["status"] == "skipped" else report.ran).append(key)
            _update(bar, log, cells, report)
    finally:
        if bar is not None:
            bar.close()
    report.wall_seconds = time.perf_counter() - start
    return report


def _check_names(cells, folders) -> None:

    for folder in folders:
        registry.ensure_folder(folder)
    registry.require(*sorted({k.participant for k in cells}))
    drawn = sorted({k.participant for k in cells if k.instance != 0} - set(builtin.BUILTIN))
    if drawn:
        raise ParticipantError(
            f"instances k >= 1 draw a hidden truth and trials for a built-in participant {builtin.BUILTIN}, "
            f"but {', '.join(drawn)} is not one: run it on instance 0 (its own trials)"
        )

    for name in sorted({k.optimizer for k in cells}):
        optimizers.get(split_prior(name)[0])  # UnknownOptimizerError lists the registered ones


def _prepare_storage(cells, storage) -> None:
    """Create the Optuna storage's tables once, before parallel workers open it."""

    if (
        isinstance(storage, str)
        and STORAGE_PER_CELL not in storage
        and any(accepts_storage(optimizers.get(split_prior(k.optimizer)[0])) for k in cells)
    ):
        open_url(storage)


def _bar(progress, total, initial, n_cells, n_done):
    if not progress:
        return None
    from tqdm import tqdm

    bar = tqdm(
        total=total, initial=initial, unit="eval", desc="benchmark", dynamic_ncols=True, smoothing=0.05, mininterval=1.0
    )
    bar.set_postfix_str(f"cells {n_done}/{n_cells}", refresh=False)
    return bar


def _update(bar, log: RunLog, cells, report) -> None:
    if bar is None:
        return
    progress = log.progress()
    n = sum(min(progress.get(k.name, 0), k.budget) for k in cells)
    if n > bar.n:
        bar.update(n - bar.n)
    bar.set_postfix_str(
        f"cells {len(report.ran) + len(report.skipped)}/{len(cells)}"
        + (f", {len(report.failed)} failed" if report.failed else ""),
        refresh=False,
    )


def _tick(bar):
    def tick(n_new, nfev):
        if bar is not None and n_new:
            bar.update(n_new)

    return tick
