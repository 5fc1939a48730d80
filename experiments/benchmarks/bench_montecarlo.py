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
[--participants P1] [--scheduler ADDRESS]`. Compare `--workers 0` (one process, a batch's designs on
one thread per core) with `--workers 2` (two processes, one thread each). On a shared machine expect
±15 %.
"""

from __future__ import annotations

import argparse
import tempfile
import time

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
    p.add_argument("--out", help="keep the log here (default: a temporary folder)")
    args = p.parse_args(argv)

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


if __name__ == "__main__":
    raise SystemExit(main())
