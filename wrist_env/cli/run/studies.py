"""How `wrist-bench` runs the studies: calibrate, benchmark, leaderboard, iohanalyzer, montecarlo,
montecarlo-report, checksum (declared in `wrist_env.cli.study_commands`)."""

from __future__ import annotations

import importlib.util
import json
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import optimizers
from wrist_env import bench
from wrist_env.bench.calibrate import PRIOR_SUFFIX, accepts_storage, split_prior
from wrist_env.bench.cells import SEED_IS_INSTANCE, make_cells
from wrist_env.bench.iohanalyzer import export
from wrist_env.bench.leaderboard import reference, write_leaderboard
from wrist_env.bench.log import RunLog
from wrist_env.bench.runner import NO_STORAGE
from wrist_env.cli.run.outputs import out_file, out_folder
from wrist_env.errors import Interrupted, StoreError, UsageError, WristEnvError
from wrist_env.ligaments import LIGAMENT_NAMES
from wrist_env.montecarlo.config import StudyConfig
from wrist_env.montecarlo.log import read_runs
from wrist_env.montecarlo.report import write_report
from wrist_env.montecarlo.study import run_study
from wrist_env.motions import TRIAL_MOTIONS
from wrist_env.participants import builtin, registry
from wrist_env.runs.executor import SchedulerError

RESUME = "rerun the same command to resume"


def calibrate(args) -> int:

    registry.require(args.participant)
    if args.out is not None:
        out_file(args.out)
    if args.log is not None:
        out_folder(args.log, "--log")
    storage = _calibrate_storage(args.storage, args.optimizer)
    start = time.perf_counter()
    name = args.optimizer + (PRIOR_SUFFIX if args.prior and not args.optimizer.endswith(PRIOR_SUFFIX) else "")
    saved = (
        f"the evaluations logged in {args.log} are kept: {RESUME}"
        if args.log
        else "nothing was saved (with --log <folder> a run can be resumed)"
    )
    seed = args.instance if args.seed is None else args.seed  # a run on instance k uses seed k unless told
    try:
        run = bench.calibrate(
            args.participant, name, args.budget, seed, log=args.log, storage=storage, instance=args.instance
        )
    except KeyboardInterrupt:
        raise Interrupted(f"calibration interrupted; {saved}") from None
    wall = time.perf_counter() - start
    ref = reference(args.participant, args.instance)
    out = run.to_dict(history=True)
    out["wall_seconds"] = round(wall, 3)
    out["population"] = {m: ref.population[m]["cost"] for m in TRIAL_MOTIONS}
    out["truth"] = None if ref.truth is None else {m: ref.truth[m]["cost"] for m in TRIAL_MOTIONS}
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(out, indent=1, allow_nan=False))
    if args.json:
        print(json.dumps(out, indent=1, allow_nan=False))
        return 0
    truth = out["truth"]
    print(
        f"{run.key.problem}: {name}, seed {seed}: {run.result.nfev} evaluations"
        f"{f' ({run.replayed} replayed from the log)' if run.replayed else ''} in {wall:.1f} s; {run.result.message}"
    )
    for motion, name in (("calibrate", "calibration trial"), ("validate", "held-out resisted trial")):
        score = getattr(run, motion)
        print(
            f"{name + ' cost:':<30} population {out['population'][motion]:.3f} -> calibrated {score['cost']:.3f}"
            + ("" if truth is None else f"  (hidden truth {truth[motion]:.3f})")
            + (" FAILED" if score["failed"] else "")
        )
    if run.recovery_z is not None:
        print(
            f"{'parameter recovery:':<30} {run.recovery_z:.3f} SD from the truth (population design "
            f"{run.recovery_z_population:.3f})"
        )
    d = run.design
    print("calibrated design (injury scalars intact):")
    print(f"  {'ligament':<8} {'stiffness N/mm':>15} {'reference strain':>17}")
    for i, lig in enumerate(LIGAMENT_NAMES):
        print(f"  {lig:<8} {d.stiffness[i]:15.2f} {d.reference_strain[i]:17.4f}")
    if args.out:
        print(f"written to {args.out} (usable as --design of simulate and evaluate)")
    return 0


def _calibrate_storage(storage: str | None, optimizer: str) -> str | None:
    """The Optuna storage URL of `calibrate --storage` (None: in memory), checked before the run: "memory" is
    none, a calibrator that keeps no Optuna study refuses one (it would be ignored), and a URL that Optuna
    cannot open is named by `optimizers.optuna_storage.open_url`."""
    if storage is None or storage in NO_STORAGE:
        return None
    cls = optimizers.get(split_prior(optimizer)[0])  # an unknown name: UnknownOptimizerError lists them
    if not accepts_storage(cls):
        takes = [n for n in optimizers.available() if accepts_storage(optimizers.get(n))]
        raise UsageError(
            f"--storage {storage!r}: {optimizer} keeps no Optuna study; --storage is for {', '.join(takes)}"
        )
    from optimizers.optuna_storage import open_url

    open_url(storage)  # InputError naming the URL if it cannot be opened (tables created, as the run would)
    return storage


def benchmark(args) -> int:

    out_folder(args.out)
    if args.leaderboard is not None:
        out_folder(args.leaderboard, "--leaderboard")
    participants = args.participants or list(builtin.BUILTIN)
    names = args.optimizers or list(optimizers.available())
    if args.prior:
        names = list(dict.fromkeys(names + [n + PRIOR_SUFFIX for n in names if not n.endswith(PRIOR_SUFFIX)]))
    seeds, instances = benchmark_seeds(args.seeds, args.instances, participants)
    cells = make_cells(participants, names, seeds, args.budget, instances)
    where = f"the dask scheduler {args.scheduler}" if args.scheduler else "local processes"
    print(
        f"{len(cells)} cells: participants {', '.join(participants)}{_instances_text(cells)} x calibrators "
        f"{', '.join(names)} x {_seeds_text(seeds)}, budget {args.budget}; on {where}; run log {args.out}",
        flush=True,
    )
    try:
        report = bench.benchmark(
            participants,
            names,
            seeds,
            args.budget,
            args.out,
            instances=instances,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=not args.no_progress,
            storage=args.storage,
            threads=args.threads,
            folders=tuple(args.folder or ()),
        )
    except KeyboardInterrupt:
        raise Interrupted(f"benchmark interrupted; {_benchmark_saved(args.out)}") from None
    except SchedulerError as e:
        raise SchedulerError(f"{e}; {_benchmark_saved(args.out)}") from None
    print(
        f"ran {len(report.ran)} cells, skipped {len(report.skipped)} already finished, "
        f"{len(report.failed)} failed; {report.evaluations} evaluations logged"
    )
    for key, error in report.failed:
        print(f"  failed {key.name}: {error}", file=sys.stderr)
    if args.scheduler is None:
        print(f"local: {report.workers} worker process(es) x {report.threads} Numba thread(s)")
    print(f"wall time {report.wall_seconds:.1f} s")
    leaderboard = Path(args.leaderboard) if args.leaderboard else Path(args.out) / "leaderboards"
    if report.ran or report.skipped:
        path = write_leaderboard(args.out, leaderboard)
        print(f"leaderboard: {path}")
    return 1 if report.failed else 0


DEFAULT_SEEDS = 5
"""`benchmark --seeds` without --instances: seeds 0 … 4 on instance 0 (the benchmark before instances); also the
default of a benchmark with a participant that is not built in (instances are drawn for built-ins only)."""
DEFAULT_INSTANCES = (0, 1, 2, 3, 4)
"""`benchmark` without --seeds and --instances on built-in participants: instances 0 … 4 (0 the shipped problem),
one run each seeded with its instance (COCO's convention): five problems per participant, the budget of the
five seeds on instance 0 it replaced."""


def benchmark_seeds(
    seeds: int | None, instances: int | list[int] | None, participants: Sequence[str]
) -> tuple[int | str, int | list[int] | None]:
    """(seeds, instances) of `benchmark`'s cells (`make_cells`' arguments). --seeds and --instances as given;
    --instances alone: one run per instance seeded with it (`SEED_IS_INSTANCE`); --seeds alone: instance 0;
    neither: `DEFAULT_INSTANCES` seeded with themselves on built-in participants, else `DEFAULT_SEEDS` on
    instance 0."""
    if instances is None and seeds is None:
        if all(p in builtin.BUILTIN for p in participants):
            return SEED_IS_INSTANCE, list(DEFAULT_INSTANCES)
        return DEFAULT_SEEDS, None
    return (SEED_IS_INSTANCE if seeds is None else seeds), instances


def _instances_text(cells) -> str:
    """ " (instances 1, 2, 3)" of the cells, or "" when they are all instance 0."""
    instances = sorted({k.instance for k in cells})
    if instances == [0]:
        return ""
    if len(instances) > 2 and instances == list(range(instances[0], instances[-1] + 1)):
        return f" (instances {instances[0]}-{instances[-1]})"
    return f" (instances {', '.join(str(k) for k in instances)})"


def _seeds_text(seeds: int | str) -> str:
    return "seed = instance" if seeds == SEED_IS_INSTANCE else f"{seeds} seeds"


def _benchmark_saved(out: str) -> str:
    """What an interrupted benchmark leaves in `out`, and how to go on."""
    try:
        evaluations = sum(RunLog(out).progress().values())
    except (WristEnvError, OSError):
        return f"what is logged in {out} is kept: {RESUME}"
    return (
        f"{evaluations:,} evaluations logged in {out} are kept (finished cells are skipped, cut ones resume): {RESUME}"
    )


def leaderboard(args) -> int:

    if not Path(args.runs).is_dir():
        raise UsageError(f"no run log at {args.runs}")
    out_folder(args.out)
    if not RunLog(args.runs).summaries():
        raise StoreError(
            f"{args.runs}: holds no finished benchmark cell, so there is no leaderboard to write; run "
            f"`wrist-bench benchmark --out {args.runs}` (again, to finish its cells)"
        )
    path = write_leaderboard(args.runs, args.out, title=args.title)
    print(path)
    return 0


def iohanalyzer(args) -> int:

    if importlib.util.find_spec("ioh") is None:
        raise SystemExit('wrist-bench iohanalyzer needs ioh, which is not installed: pip install -e ".[ioh]"')
    if not Path(args.runs).is_dir():
        raise UsageError(f"no run log at {args.runs}")
    out_folder(args.out)
    for folder in export(args.runs, args.out):
        print(folder)
    return 0


def montecarlo(args) -> int:

    registry.require(*args.participants)
    out_folder(args.out)
    config = StudyConfig(
        tuple(args.participants), args.n, args.seed, args.tear_probability, load_direction=args.load_direction
    )
    where = (
        f"the dask scheduler {args.scheduler}"
        if args.scheduler
        else f"{args.workers} local worker processes"
        if args.workers > 1
        else "this process (Numba threads on every core)"
    )
    print(
        f"Monte Carlo: {', '.join(config.participants)}, {config.n:,} successful runs each, seed {config.seed}, "
        f"load {config.load_direction}, "
        f"batch {args.batch}, on {where}; run log {args.out}",
        flush=True,
    )
    try:
        summary = run_study(
            config,
            args.out,
            batch=args.batch,
            scheduler=args.scheduler,
            workers=args.workers,
            folders=tuple(args.folder or ()),
            progress=not args.no_progress,
        )
    except KeyboardInterrupt:
        raise Interrupted(f"Monte Carlo study interrupted; {_montecarlo_saved(args.out)}") from None
    except SchedulerError as e:
        raise SchedulerError(f"{e}; {_montecarlo_saved(args.out)}") from None
    print(summary.line())
    return 0


def _montecarlo_saved(out: str) -> str:
    """What an interrupted Monte Carlo study leaves in `out`, and how to go on."""
    try:
        table = read_runs(out)
    except (WristEnvError, OSError):
        return f"the runs logged in {out} are kept: {RESUME}"
    runs = 0 if table is None else table.num_rows
    return f"{runs:,} runs logged in {out} are kept (every finished batch): {RESUME}"


def montecarlo_report(args) -> int:

    if not Path(args.runs).is_dir():
        raise UsageError(f"no Monte Carlo run log at {args.runs}")
    out_folder(args.out)
    summary = write_report(args.runs, args.out, max_runs=args.max_runs)
    t5 = summary["table5"]
    print(
        f"Table 5: {t5['runs']:,} runs, {t5['rows']:,} rows, fit {t5['fit_seconds']} s; "
        f"report {summary['report_seconds']} s; written to {args.out}"
    )
    return 0


def checksum(args) -> int:
    from wrist_env.runs.store import add_checksums

    done = add_checksums(args.run_log)
    for path in done:
        print(f"checksummed {path}")
    print(
        f"{len(done)} files checksummed in {args.run_log}" if done else f"{args.run_log}: every file has its checksum"
    )
    return 0
