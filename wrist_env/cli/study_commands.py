"""`wrist-bench` studies: calibrate, benchmark, leaderboard, iohanalyzer, montecarlo, montecarlo-report (their
arguments; `wrist_env.cli.run.studies` runs them)."""

from __future__ import annotations

import argparse
from collections.abc import Callable

import optimizers
from wrist_env.cli.options import (
    INSTANCE,
    instances_option,
    json_option,
    load_direction_option,
    out_option,
    participant_argument,
    participants_argument,
    progress_option,
    scheduler_option,
    seed_option,
)
from wrist_env.design import SPAN_SD
from wrist_env.ligaments import INJURABLE
from wrist_env.limits import (
    MAX_BATCH,
    MAX_BUDGET,
    MAX_RUNS,
    MAX_SEEDS,
    MAX_SUBSET_RUNS,
    MAX_THREADS,
    MAX_WORKERS,
    bounded_float,
    bounded_int,
)
from wrist_env.montecarlo.config import EXCLUDE_ABOVE_MPA, FIT_RUNS_WHY, MIN_FIT_RUNS, TEAR_PROBABILITY

BUDGET = bounded_int("budget", 1, MAX_BUDGET)
"""`--budget` of calibrate and benchmark: simulations of one calibration."""


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
    s.add_argument("--budget", type=BUDGET, default=300, help="simulations allowed (default 300)")
    s.add_argument(
        "--instance",
        type=INSTANCE,
        default=0,
        help="problem instance of a built-in participant: 0 (default) its shipped truth and trials, K >= 1 a "
        "hidden truth drawn from the prior and the trials made from it (made and cached on first use)",
    )
    seed_option(s, "calibrator", None, "the instance, as the benchmark seeds a run on instance k")
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
    s.set_defaults(run="studies:calibrate")

    s = command(
        "benchmark",
        description="Cross participants x instances x calibrators x seeds, one cell each, on local processes (default) or a "
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
    s.add_argument(
        "--seeds",
        type=bounded_int("seeds", 1, MAX_SEEDS),
        help="seeds 0 .. N-1 per participant, instance and calibrator (without --instances: on instance 0, the "
        "shipped problem; default: one run per instance, seeded with the instance)",
    )
    instances_option(s)
    s.add_argument("--budget", type=BUDGET, default=300, help="simulations per run (default 300)")
    out_option(s, "runs/benchmark", "run-log folder")
    scheduler_option(s, "cell")
    s.add_argument(
        "--workers", type=bounded_int("workers", 1, MAX_WORKERS), help="local worker processes (default: one per core)"
    )
    s.add_argument(
        "--threads",
        type=bounded_int("threads", 1, MAX_THREADS),
        help="Numba threads per local worker (default: cores / workers)",
    )
    s.add_argument(
        "--storage",
        help="Optuna storage URL, '{cell}' replaced by the cell's key (default: "
        "sqlite:///<out>/optuna/{cell}.db); 'memory': studies in memory only",
    )
    s.add_argument("--leaderboard", help="leaderboard folder (default: <out>/leaderboards)")
    progress_option(s)
    s.set_defaults(run="studies:benchmark")

    s = command(
        "leaderboard",
        description="Tables (Markdown, CSV) and figures (PNG) from a benchmark run log, per participant "
        "pooling its instances: best cost at the budget, evaluations to cost targets (ERT with bootstrapped "
        "90 % intervals), ECDF and convergence plots, the ranking over problems (Friedman test, critical-"
        "difference diagram), parameter recovery, the held-out trial, the preprint's Tables 3-4.",
    )
    _run_log_arguments(s, out="runs/leaderboard")
    s.add_argument("--title", help="title of the README.md")
    s.set_defaults(run="studies:leaderboard")

    s = command(
        "iohanalyzer",
        description="Replays every logged evaluation through ioh's Analyzer logger (nothing is simulated): "
        "one folder per calibrator, one problem per participant (wrist-<participant>), one run per instance and "
        "seed, each with its instance id. "
        "Zip the output folder and upload it to IOHanalyzer. Needs the [ioh] extra.",
    )
    _run_log_arguments(s, out="runs/iohanalyzer")
    s.set_defaults(run="studies:iohanalyzer")

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
    s.add_argument(
        "--n",
        type=bounded_int("n", 1, MAX_RUNS, "a round's draws are held in memory"),
        default=12500,
        help="successful runs per participant (default 12500)",
    )
    seed_option(s, "study")
    s.add_argument(
        "--tear-probability",
        type=bounded_float("tear probability", 0.0, 1.0),
        default=TEAR_PROBABILITY,
        help=f"chance of each tear (default {TEAR_PROBABILITY:g})",
    )
    load_direction_option(s, "the sweeps' load: along the radius (default), or a tendon rig's resultant (see validate)")
    out_option(s, "runs/montecarlo", "run-log folder")
    scheduler_option(s, "batch")
    s.add_argument(
        "--batch",
        type=bounded_int("batch", 1, MAX_BATCH),
        default=64,
        help="runs per batch: one vector-env step, one log part (default 64)",
    )
    s.add_argument(
        "--workers",
        type=bounded_int("workers", 0, MAX_WORKERS, "0 or 1: this process"),
        default=0,
        help="local worker processes, which die with this one (default 0, or 1: this process, "
        "Numba threads on every core)",
    )
    progress_option(s)
    s.set_defaults(run="studies:montecarlo")

    s = command(
        "montecarlo-report",
        folders_option=False,
        description="Mixed-effects fits (statsmodels MixedLM) of radioscaphoid pressure on a 2-df "
        "angle spline and the tears (Table 5) and of SLIL bundle forces in intact runs "
        "(Table 6), with a random intercept per run; tables as Markdown and CSV, figures "
        "as PNG, summary.json and report.md.",
    )
    _run_log_arguments(s, out="runs/montecarlo-report", runs="runs/montecarlo")
    s.add_argument(
        "--max-runs",
        type=bounded_int("max_runs", MIN_FIT_RUNS, MAX_SUBSET_RUNS, FIT_RUNS_WHY),
        help=f"fit on a seeded random subset of this many runs, at least {MIN_FIT_RUNS} (default: all)",
    )
    s.set_defaults(run="studies:montecarlo_report")

    s = command(
        "checksum",
        folders_option=False,
        description="Add the checksums a run log written before wrist-env kept them lacks (a benchmark's --out or "
        "a Monte Carlo study's): every Parquet part that reads whole gets its .sha256, every cell summary its "
        "record_sha256, and each is named. A log missing a checksum is otherwise refused as damaged, since a "
        "deleted checksum looks the same: run this only on a log you trust.",
    )
    s.add_argument("run_log", metavar="folder", help="the run-log folder")
    s.set_defaults(run="studies:checksum")
