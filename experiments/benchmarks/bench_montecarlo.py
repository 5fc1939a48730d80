"""Benchmark: the Monte Carlo study's throughput, and the projected time of the preprint's full size.

Runs a small study (default: P1, n = 500, seed 0, batch 64, in this process)
into a temporary folder through the same code as `wrist-bench montecarlo`
(`wrist_env.montecarlo.run_study`: the Idealized vector env, the Parquet log),
after a warm-up chunk that loads the model and Numba's cache, and prints:

- simulations per second (all runs, excluded and failed included);
- the exclusion and failure rates;
- the projected wall time of 2 participants x 12,500 successful runs
  (attempts = 25,000 / (1 - exclusion rate - failure rate), at this rate),
  beside the preprint's 13 days.

Run: `python experiments/benchmarks/bench_montecarlo.py [--n 500] [--batch 64] [--workers 0]
[--participants P1] [--scheduler ADDRESS] [--against PATH --rounds 2 --out FILE]`. Compare `--workers 0`
(one process, a batch's designs on one thread per core) with `--workers 2` (two processes, one thread
each). With `--against PATH` (another checkout, e.g. a worktree of main) the same study runs in a fresh
process of each checkout in turn (A B A B …), each over its own warm Numba cache, and a table gives the
medians and their ratio this / against (`--out`: also as Markdown, with both commits). On a shared
machine expect ±15 %.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

PREPRINT_SECONDS = 13 * 24 * 3600.0
FULL = 2 * 12_500


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--participants", nargs="+", default=["P1"])
    p.add_argument("--n", type=int, default=500)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--batch", type=int, default=64)
    p.add_argument("--workers", type=int, default=0)
    p.add_argument("--scheduler")
    p.add_argument(
        "--out", help="keep the log here (default: a temporary folder); with --against: the table (Markdown)"
    )
    p.add_argument("--against", type=Path, help="another checkout to compare with, in turn")
    p.add_argument(
        "--rounds", type=int, default=2, help="with --against: studies of each checkout, in turn (default 2)"
    )
    p.add_argument("--json", action="store_true", help="print the figures as one JSON line (what --against reads)")
    args = p.parse_args(argv)
    if args.against:
        return _compare(args)

    import numba

    from wrist_env.montecarlo import StudyConfig, run_study
    from wrist_env.montecarlo.sampler import block_actions, run_chunk

    start = time.perf_counter()
    for name in args.participants:  # model, env, Numba cache: not part of the rate
        run_chunk(name, [0], [0], block_actions(99, name, 0, 1))
    warm = time.perf_counter() - start
    with tempfile.TemporaryDirectory() as tmp:
        out = args.out or tmp
        config = StudyConfig(tuple(args.participants), args.n, args.seed)
        summary = run_study(config, out, batch=args.batch, workers=args.workers, scheduler=args.scheduler)
    rate = summary.simulated / summary.wall_seconds
    bad = (summary.excluded + summary.failed) / max(summary.attempts, 1)
    projected = FULL / (1.0 - bad) / rate
    mode = (
        f"scheduler {args.scheduler}"
        if args.scheduler
        else f"{args.workers} local worker processes"
        if args.workers
        else f"one process, {numba.get_num_threads()} Numba threads"
    )
    if args.json:
        figures = {
            "simulations/s": rate,
            "excluded and failed, %": 100 * bad,
            "projected 2 x 12,500 successful runs, min": projected / 60,
        }
        print(json.dumps(figures))
        return 0
    print(
        f"Monte Carlo {', '.join(args.participants)}, n = {args.n} each, seed {args.seed}, batch {args.batch}, {mode}"
    )
    print(f"warm-up (model, env, Numba cache): {warm:.1f} s")
    print(f"{summary.simulated} simulations in {summary.wall_seconds:.1f} s: {rate:.1f} simulations/s")
    print(
        f"excluded {summary.excluded} ({100 * summary.excluded / summary.attempts:.2f} %), "
        f"failed {summary.failed} ({100 * summary.failed / summary.attempts:.2f} %) of {summary.attempts} runs"
    )
    print(
        f"projected 2 x 12,500 successful runs: {projected / 60:.1f} min "
        f"(preprint: 13 days, {PREPRINT_SECONDS / projected:,.0f}x faster)"
    )
    return 0


def _compare(args) -> int:
    """The study in a fresh process of each checkout in turn (this script, the checkout's package), the
    medians and their ratio."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from bench_cold_start import HERE, _run, write_table  # experiments/benchmarks/bench_cold_start.py

    own = ["--participants", *args.participants, "--n", str(args.n), "--seed", str(args.seed)]
    own += ["--batch", str(args.batch), "--workers", str(args.workers)]
    own += ["--scheduler", args.scheduler] if args.scheduler else []
    trees = {"this": HERE, "against": args.against.resolve()}
    runs = {name: [] for name in trees}
    for r in range(args.rounds):
        for name, tree in trees.items():
            cache = (
                Path(tempfile.gettempdir()) / f"wrist-env-montecarlo-{hashlib.sha1(str(tree).encode()).hexdigest()[:8]}"
            )
            _, out = _run(tree, cache, [str(Path(__file__).resolve()), *own, "--json"])
            runs[name].append(json.loads(out.strip().splitlines()[-1]))
            print(f"round {r + 1}/{args.rounds}, {name}: done", file=sys.stderr, flush=True)
    head = f"Monte Carlo {', '.join(args.participants)}, n = {args.n} each, batch {args.batch}, workers {args.workers}"
    lines = [f"| {head}: figure (median of {args.rounds}) | this | against | this / against |", "|---|---|---|---|"]
    for k in runs["this"][0]:
        this, that = (float(np.median([m[k] for m in runs[name]])) for name in trees)
        lines.append(f"| {k} | {this:,.2f} | {that:,.2f} | {this / that:.2f} |")
    print("\n".join(lines))
    if args.out:
        write_table(Path(args.out), "bench_montecarlo.py", trees, lines)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
