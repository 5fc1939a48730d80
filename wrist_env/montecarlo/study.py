"""The Monte Carlo study: n successful runs per participant, logged as chunks finish, resumable.

Rounds (per participant): round 0 runs block 0, a Latin hypercube of n draws
(sample ids 0 … n−1). When a round is complete, the runs that failed in the
solver or were excluded (`sampler` docstring) are counted, and round r + 1
runs block r + 1, a fresh Latin hypercube of exactly as many draws as are
missing, with the next sample ids — until n runs have succeeded. Every draw is
a pure function of (seed, participant, block, size) and every outcome of its
draw, so the set of runs, and the log, do not depend on batch size, worker
count, scheduler, or on being killed and resumed.

Log: a run store (`wrist_env.runs.store.RunStore`, the benchmark's too):
`<out>/runs/<participant>-<first id>-<end id>.parquet`, one part per chunk,
written atomically by this process as the chunk finishes (rows:
`sampler.SCHEMA`), and `<out>/study.json` (participants, n, seed, tear
probability, exclusion threshold). Rerunning the same command resumes: logged
runs are read back, only missing sample ids are simulated; a damaged part is
moved to `<out>/damaged/` and its runs simulated again. A different seed, n,
tear probability or threshold in the same folder is refused, and so is a
second run while one is writing to the folder (`<out>/locks/store.lock`).

Where chunks run (`wrist_env.runs.executor`, the benchmark's too): in this
process (`workers` 0 or 1: one batched call at a time, its designs on one thread
per core — the default, measured fastest on this 2-core machine), in `workers`
local processes (each with cores / workers Numba threads; they die with this
process), or on a `dask.distributed` scheduler (`scheduler="tcp://…"`, or a
`distributed.Client`); workers only compute, this process writes the log.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from wrist_env.errors import InputError
from wrist_env.limits import MAX_BATCH, MAX_WORKERS, check_int
from wrist_env.montecarlo import sampler
from wrist_env.montecarlo.config import StudyConfig, StudyError
from wrist_env.montecarlo.log import (
    RERUN,
    RUNS,
    _manifest,
    check_settings,
    part_name,
    read_manifest,
    read_runs,
    repair,
    runs_log,
    with_settings,
)
from wrist_env.participants import registry
from wrist_env.runs import provenance
from wrist_env.runs.executor import executor

if TYPE_CHECKING:
    from distributed import Client


@dataclass
class ParticipantCounts:
    """A participant's runs so far: attempts = succeeded + excluded + failed."""

    participant: str
    attempts: int = 0
    succeeded: int = 0
    excluded: int = 0
    failed: int = 0
    blocks: int = 0


@dataclass
class StudySummary:
    config: StudyConfig
    counts: dict[str, ParticipantCounts]
    simulated: int = 0
    """Runs simulated by this call (resumed runs not included)."""
    wall_seconds: float = 0.0
    out: Path | None = None
    done: bool = False
    extra: dict = field(default_factory=dict)

    @property
    def excluded(self) -> int:
        return sum(c.excluded for c in self.counts.values())

    @property
    def failed(self) -> int:
        return sum(c.failed for c in self.counts.values())

    @property
    def attempts(self) -> int:
        return sum(c.attempts for c in self.counts.values())

    def line(self) -> str:
        rate = self.simulated / self.wall_seconds if self.wall_seconds > 0 else float("nan")
        per = "; ".join(
            f"{p} {c.succeeded} ok, {c.excluded} excluded, {c.failed} failed" for p, c in self.counts.items()
        )
        return (
            f"wall {self.wall_seconds:.1f} s for {self.simulated} simulations ({rate:.1f}/s); "
            f"excluded {self.excluded} ({100 * self.excluded / max(self.attempts, 1):.2f} %), "
            f"failed {self.failed} ({100 * self.failed / max(self.attempts, 1):.2f} %) of {self.attempts} runs; {per}"
        )


# ---------------------------------------------------------------------------- rounds


@dataclass(frozen=True)
class Round:
    participant: str
    block: int
    start: int
    size: int
    missing: tuple[int, ...]


def _plan(participant: str, config: StudyConfig, outcomes: dict) -> tuple[Round | None, ParticipantCounts]:
    """The participant's first incomplete round (None when n runs succeeded) and its counts so far.

    outcomes: {sample_id: (ok, excluded)} of the logged runs.
    """
    counts = ParticipantCounts(participant)
    start, size, block = 0, int(config.n), 0
    while True:
        ids = range(start, start + size)
        missing = tuple(i for i in ids if i not in outcomes)
        for i in ids:
            if i in outcomes:
                ok, excluded = outcomes[i]
                counts.attempts += 1
                counts.succeeded += ok and not excluded
                counts.excluded += ok and excluded
                counts.failed += not ok
        counts.blocks = block + 1
        if missing:
            return Round(participant, block, start, size, missing), counts
        deficit = int(config.n) - counts.succeeded
        if deficit <= 0:
            return None, counts
        start, block, size = start + size, block + 1, deficit
        if start + size > config.attempt_limit:
            raise StudyError(
                f"{participant}: {counts.attempts} runs gave only {counts.succeeded} of {config.n} "
                f"successes ({counts.excluded} excluded, {counts.failed} failed); giving up"
            )


def _chunks(ids: tuple[int, ...], batch: int) -> Iterator[tuple[int, ...]]:
    """Consecutive runs of ids, at most `batch` long."""
    run: list[int] = []
    for i in ids:
        if run and (i != run[-1] + 1 or len(run) == batch):
            yield tuple(run)
            run = []
        run.append(i)
    if run:
        yield tuple(run)


# ---------------------------------------------------------------------------- the study


def run_study(
    config: StudyConfig,
    out: str | Path,
    *,
    batch: int = 64,
    scheduler: str | Client | None = None,
    workers: int = 0,
    folders: Iterable[str | Path] = (),
    progress: bool = False,
) -> StudySummary:
    """Run (or resume) a study into the folder `out`; returns the counts and the wall time.

    Parameters
    ----------
    config : StudyConfig
        The study: participants, n, seed, tear probability, exclusion threshold, load direction.
    out : str or Path
        The study's folder (made if missing); a study already logged there resumes.
    batch : int, default 64
        Runs per chunk (one vector-env step, one log part), in [1, `limits.MAX_BATCH`].
    scheduler : str or distributed.Client, optional
        A dask.distributed address or Client (default: local).
    workers : int, default 0
        Local worker processes (0 or 1: this process).
    folders : iterable of str or Path, default ()
        User participant folders (registered here and on every worker).
    progress : bool, default False
        A tqdm bar of successful runs (postfix: excluded and failed so far).

    Returns
    -------
    StudySummary
        Per participant its attempts, successes, exclusions and failures (``counts``), the runs simulated by
        this call (``simulated``), the wall time (``wall_seconds``, s) and whether the study is done.

    Raises
    ------
    StoreBusyError
        A second run on the same `out` while this one is running.
    InputError
        An empty `out` (it would be the current folder), or batch or workers out of range.
    StudyError
        `out` holds runs made with other settings or on another model, or a participant reached its attempt
        limit.
    """
    if not str(out).strip():
        raise InputError("out is empty; give the study's folder (run_study(config, 'runs/montecarlo'))")
    batch = check_int("batch", batch, 1, MAX_BATCH)
    workers = check_int("workers", workers, 0, MAX_WORKERS, "0 or 1: this process")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with runs_log(out).lock(wait=False, what=f"a Monte Carlo study in {out}"):
        return _run_locked(config, out, batch, scheduler, workers, tuple(str(f) for f in folders), progress)


def _logged_outcomes(out: Path, participants) -> dict[str, dict[int, tuple[bool, bool]]]:
    """{participant: {sample_id: (ok, excluded)}} of the logged runs."""
    outcomes: dict[str, dict[int, tuple[bool, bool]]] = {p: {} for p in participants}
    logged = read_runs(out, None)
    if logged is not None:
        cols = logged.select(["participant", "sample_id", "ok", "excluded"]).to_pydict()
        for p, s, ok, ex in zip(cols["participant"], cols["sample_id"], cols["ok"], cols["excluded"]):
            outcomes.setdefault(p, {})[int(s)] = (bool(ok), bool(ex))
    return outcomes


def _run_locked(
    config: StudyConfig, out: Path, batch: int, scheduler, workers, folders: tuple, progress: bool
) -> StudySummary:
    start_time = time.perf_counter()
    for f in folders:
        registry.ensure_folder(f)
    made_from = functools.cache(provenance.of_participant)  # what every part records; loaded when first
    check_settings(out, config, made_from)  # needed (by then a worker has built a folder's model)
    _manifest(out, config)
    repair(out)
    log = runs_log(out)
    outcomes = _logged_outcomes(out, config.participants)

    summary = StudySummary(config, {}, out=out)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=config.n * len(config.participants), unit="run", desc="Monte Carlo", smoothing=0.05)
    try:
        with executor(scheduler, workers, warm=registry.warm_solver) as ex:
            while True:
                rounds = {}
                for p in config.participants:
                    rnd, summary.counts[p] = _plan(p, config, outcomes[p])
                    if rnd is not None:
                        rounds[p] = rnd
                excluded, failed = summary.excluded, summary.failed
                if bar is not None:
                    bar.n = sum(c.succeeded for c in summary.counts.values())
                    bar.set_postfix(excluded=excluded, failed=failed)
                    bar.refresh()
                if not rounds:
                    summary.done = True
                    break
                tasks = []
                for p, rnd in rounds.items():
                    block = sampler.block_actions(config.seed, p, rnd.block, rnd.size, config.tear_probability)
                    for ids in _chunks(rnd.missing, batch):
                        rows = np.asarray(ids) - rnd.start
                        tasks.append(
                            ex.submit(
                                sampler.run_chunk,
                                p,
                                ids,
                                [rnd.block] * len(ids),
                                block[rows],
                                exclude_above_mpa=config.exclude_above_mpa,
                                folders=folders,
                                load_direction=config.load_direction,
                            )
                        )
                for _, table, error in ex.results(tasks):
                    if error is not None:
                        raise error
                    cols = table.select(["participant", "sample_id", "ok", "excluded"]).to_pydict()
                    p = cols["participant"][0]
                    ids = tuple(int(s) for s in cols["sample_id"])
                    log.write_part(part_name(p, ids), with_settings(table, config, made_from(p)))
                    good = 0
                    for s, ok, ex_ in zip(ids, cols["ok"], cols["excluded"]):
                        outcomes[p][s] = (bool(ok), bool(ex_))
                        good += bool(ok) and not bool(ex_)
                        excluded += bool(ok) and bool(ex_)
                        failed += not bool(ok)
                    summary.simulated += len(ids)
                    if bar is not None:
                        bar.update(good)
                        bar.set_postfix(excluded=excluded, failed=failed)
    finally:
        if bar is not None:
            bar.close()
    for p in config.participants:  # recount from the log's outcomes
        summary.counts[p] = _plan(p, config, outcomes[p])[1]
    summary.wall_seconds = time.perf_counter() - start_time
    return summary


def config_of(out: str | Path, participants: Sequence[str] | None = None) -> StudyConfig:
    """The StudyConfig recorded in a study folder (optionally for other participants)."""
    m = read_manifest(out)
    return StudyConfig(
        tuple(participants or m["participants"]),
        m["n"],
        m["seed"],
        m["tear_probability"],
        m["exclude_above_mpa"],
        load_direction=m.get("load_direction", "axial"),
    )


def counts(out: str | Path, *, complete: bool = False) -> dict[str, ParticipantCounts]:
    """Per-participant counts of a study folder, from its log. complete: StudyError naming the
    missing runs unless every participant has its n successes (a finished study whose part was
    deleted, or one still running, would otherwise be reported with counts that disagree)."""
    config = config_of(out)
    outcomes = _logged_outcomes(Path(out), config.participants)
    out_counts = {}
    for p in config.participants:
        rnd, out_counts[p] = _plan(p, config, outcomes[p])
        if complete and rnd is not None:
            m = rnd.missing
            raise StudyError(
                f"{Path(out) / RUNS}: the study is not complete: {p} has {out_counts[p].succeeded:,} of {config.n:,} "
                f"successful runs and {len(m):,} runs of block {rnd.block} are missing (#{m[0]}…#{m[-1]}; a part "
                f"deleted, or the study still running?); {RERUN}"
            )
    return out_counts
