"""`wrist-bench` studies: calibrate, benchmark, leaderboard, iohanalyzer, montecarlo, montecarlo-report."""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path

import optimizers
from wrist_env.bench.calibrate import PRIOR_SUFFIX, calibrate
from wrist_env.bench.iohanalyzer import export
from wrist_env.bench.leaderboard import reference, write_leaderboard
from wrist_env.bench.runner import benchmark, make_cells
from wrist_env.cli.options import (
    json_option,
    load_direction_option,
    out_option,
    participant_argument,
    participants_argument,
    progress_option,
    scheduler_option,
    seed_option,
)
from wrist_env.design import INJURABLE, LIGAMENT_NAMES, SPAN_SD
from wrist_env.errors import UsageError
from wrist_env.montecarlo.report import write_report
from wrist_env.montecarlo.sampler import EXCLUDE_ABOVE_MPA, TEAR_PROBABILITY
from wrist_env.montecarlo.study import StudyConfig, run_study
from wrist_env.participants import builtin, registry
from wrist_env.trial import TRIAL_MOTIONS


def _calibrate(args) -> int:

    registry.require(args.participant)
    start = time.perf_counter()
    name = args.optimizer + (PRIOR_SUFFIX if args.prior and not args.optimizer.endswith(PRIOR_SUFFIX) else "")
    run = calibrate(args.participant, name, args.budget, args.seed, log=args.log, storage=args.storage)
    wall = time.perf_counter() - start
    ref = reference(args.participant)
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
        f"{args.participant}: {name}, seed {args.seed}: {run.result.nfev} evaluations"
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


def _benchmark(args) -> int:

    participants = args.participants or list(builtin.BUILTIN)
    names = args.optimizers or list(optimizers.available())
    if args.prior:
        names = list(dict.fromkeys(names + [n + PRIOR_SUFFIX for n in names if not n.endswith(PRIOR_SUFFIX)]))
    cells = make_cells(participants, names, args.seeds, args.budget)
    where = f"the dask scheduler {args.scheduler}" if args.scheduler else "local processes"
    print(
        f"{len(cells)} cells: participants {', '.join(participants)} x calibrators {', '.join(names)} x "
        f"{args.seeds} seeds, budget {args.budget}; on {where}; run log {args.out}",
        flush=True,
    )
    report = benchmark(
        participants,
        names,
        args.seeds,
        args.budget,
        args.out,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=not args.no_progress,
        storage=args.storage,
        threads=args.threads,
        folders=tuple(args.folder or ()),
    )
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


def _leaderboard(args) -> int:

    if not Path(args.runs).is_dir():
        raise UsageError(f"no run log at {args.runs}")
    path = write_leaderboard(args.runs, args.out, title=args.title)
    print(path)
    return 0


def _iohanalyzer(args) -> int:

    if importlib.util.find_spec("ioh") is None:
        raise SystemExit('wrist-bench iohanalyzer needs ioh, which is not installed: pip install -e ".[ioh]"')
    if not Path(args.runs).is_dir():
        raise UsageError(f"no run log at {args.runs}")
    for folder in export(args.runs, args.out):
        print(folder)
    return 0


def _montecarlo(args) -> int:

    registry.require(*args.participants)
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
    summary = run_study(
        config,
        args.out,
        batch=args.batch,
        scheduler=args.scheduler,
        workers=args.workers,
        folders=tuple(args.folder or ()),
        progress=not args.no_progress,
    )
    print(summary.line())
    return 0


def _montecarlo_report(args) -> int:

    if not Path(args.runs).is_dir():
        raise UsageError(f"no Monte Carlo run log at {args.runs}")
    summary = write_report(args.runs, args.out, max_runs=args.max_runs)
    t5 = summary["table5"]
    print(
        f"Table 5: {t5['runs']:,} runs, {t5['rows']:,} rows, fit {t5['fit_seconds']} s; "
        f"report {summary['report_seconds']} s; written to {args.out}"
    )
    return 0


def _run_log_arguments(s: argparse.ArgumentParser, *, out: str, runs: str = "runs/benchmark") -> None:
    """--runs (a run log, default `runs`: the benchmark's) and --out (an output folder, default `out`) of a
    command that reads a log."""
    s.add_argument("--runs", default=runs, help=f"run-log folder (default {runs})")
    out_option(s, out)


def add_commands(command: Callable[..., argparse.ArgumentParser]) -> None:
    """Add these commands; `command(name, **kwargs)` makes a subcommand's parser."""

    s = command(
        "calibrate",
        description="Search the 22 ligament material variables (injury scalars intact) to minimize the kinematic "
        "cost on the participant's calibration trial, with a registered calibrator "
        "(`optimizers.available()`); then score the calibrated design on the held-out resisted trial "
        "and, for built-in participants, against the hidden truth (parameter recovery, Table 2 SD "
        "units). Prints the calibrated design in physical units.",
    )
    participant_argument(s)
    s.add_argument(
        "--optimizer", default="cmaes", help=f"calibrator: {', '.join(optimizers.available())} (default cmaes)"
    )
    s.add_argument("--budget", type=int, default=300, help="simulations allowed (default 300)")
    seed_option(s, "calibrator")
    s.add_argument("--log", help="run-log folder: log every batch, resume this run if it was cut short")
    s.add_argument("--storage", help="Optuna storage URL for Optuna calibrators (default: in memory)")
    s.add_argument(
        "--prior",
        action="store_true",
        help="minimize the MAP objective (kinematic misfit over the 4DCT noise + the Table 2 prior) instead of "
        "the cost; the same as the calibrator name with '+prior' appended",
    )
    out_option(s, what="also write the JSON result to this file (usable as --design elsewhere)")
    json_option(s, "the result, design and held-out cost")
    s.set_defaults(run=_calibrate)

    s = command(
        "benchmark",
        description="Cross participants x calibrators x seeds, one cell each, on local processes (default) or a "
        "dask.distributed scheduler; every evaluation is logged to Parquet in --out as its batch "
        "finishes. Run the same command again to resume after an interruption: finished cells are "
        "skipped, unfinished ones replay their logged evaluations. Writes the leaderboard at the end.",
    )
    s.add_argument("--participants", nargs="+", help="default: the built-in P1 P2 P3")
    s.add_argument(
        "--optimizers", nargs="+", help="default: every registered calibrator; '<name>+prior' for its MAP twin"
    )
    s.add_argument(
        "--prior", action="store_true", help="also run every calibrator on the MAP objective ('<name>+prior')"
    )
    s.add_argument("--seeds", type=int, default=5, help="seeds 0 .. N-1 per participant and calibrator (default 5)")
    s.add_argument("--budget", type=int, default=300, help="simulations per run (default 300)")
    out_option(s, "runs/benchmark", "run-log folder")
    scheduler_option(s, "cell")
    s.add_argument("--workers", type=int, help="local worker processes (default: one per core)")
    s.add_argument("--threads", type=int, help="Numba threads per local worker (default: cores / workers)")
    s.add_argument(
        "--storage",
        help="Optuna storage URL, '{cell}' replaced by the cell's key (default: "
        "sqlite:///<out>/optuna/{cell}.db); 'memory': studies in memory only",
    )
    s.add_argument("--leaderboard", help="leaderboard folder (default: <out>/leaderboards)")
    progress_option(s)
    s.set_defaults(run=_benchmark)

    s = command(
        "leaderboard",
        description="Tables (Markdown, CSV) and figures (PNG) from a benchmark run log: best cost "
        "at the budget, evaluations to cost targets, ECDF and convergence plots, "
        "parameter recovery, the held-out trial, the preprint's Tables 3-4.",
    )
    _run_log_arguments(s, out="runs/leaderboard")
    s.add_argument("--title", help="title of the README.md")
    s.set_defaults(run=_leaderboard)

    s = command(
        "iohanalyzer",
        description="Replays every logged evaluation through ioh's Analyzer logger (nothing is simulated): "
        "one folder per calibrator, one problem per participant (wrist-<participant>), one run per seed. "
        "Zip the output folder and upload it to IOHanalyzer. Needs the [ioh] extra.",
    )
    _run_log_arguments(s, out="runs/iohanalyzer")
    s.set_defaults(run=_iohanalyzer)

    s = command(
        "montecarlo",
        description=f"Latin hypercube over the 27 design variables (materials from Table 2's normals truncated at "
        f"+-{SPAN_SD:g} SD, each of {', '.join(INJURABLE)} torn with probability {TEAR_PROBABILITY:g}), "
        f"simulated through the Idealized environment; runs whose radioscaphoid mean pressure exceeds "
        f"{EXCLUDE_ABOVE_MPA:g} MPa at any frame are excluded and, like solver failures, replaced until n "
        f"runs succeed. Every run is logged to Parquet in --out as its batch finishes; run the same "
        f"command again to resume.",
    )
    participants_argument(s)
    s.add_argument("--n", type=int, default=12500, help="successful runs per participant (default 12500)")
    seed_option(s, "study")
    s.add_argument(
        "--tear-probability",
        type=float,
        default=TEAR_PROBABILITY,
        help=f"chance of each tear (default {TEAR_PROBABILITY:g})",
    )
    load_direction_option(s, "the sweeps' load: along the radius (default), or a tendon rig's resultant (see validate)")
    out_option(s, "runs/montecarlo", "run-log folder")
    scheduler_option(s, "batch")
    s.add_argument(
        "--batch", type=int, default=64, help="runs per batch: one vector-env step, one log part (default 64)"
    )
    s.add_argument(
        "--workers",
        type=int,
        default=0,
        help="local worker processes, which die with this one (default 0, or 1: this process, "
        "Numba threads on every core)",
    )
    progress_option(s)
    s.set_defaults(run=_montecarlo)

    s = command(
        "montecarlo-report",
        folders_option=False,
        description="Mixed-effects fits (statsmodels MixedLM) of radioscaphoid pressure on a 2-df "
        "angle spline and the tears (Table 5) and of SLIL bundle forces in intact runs "
        "(Table 6), with a random intercept per run; tables as Markdown and CSV, figures "
        "as PNG, summary.json and report.md.",
    )
    _run_log_arguments(s, out="runs/montecarlo-report", runs="runs/montecarlo")
    s.add_argument("--max-runs", type=int, help="fit on a seeded random subset of this many runs (default: all)")
    s.set_defaults(run=_montecarlo_report)
