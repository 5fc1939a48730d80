"""Benchmark: how batched simulation scales with batch size and cores, and how one simulation's
cost grows with the contact-sample resolution (issue 13).

1. Simulations per second of `simulate_batch` (the idealized sweep; the same 64 Monte Carlo designs
   at every batch size, n at a time) for batch sizes 1–64 on 1 and 2 Numba threads, and the
   2-thread / 1-thread ratio at the largest batch.
2. One sweep (population design, one thread) on P1 built at contact-sample spacings 0.7–2.0 mm:
   samples, steps, milliseconds per simulation and microseconds per step.

Writes runs/figures/scaling_<name>.png (both panels; `experiments/regenerate.py` writes the copy in experiments/figures that docs/solver.md shows). Timings are medians of repeated runs;
run it on a quiet machine (nothing else on its cores). Builds the coarser and finer P1 variants
on first use (~1 min each, cached).

Run: `python experiments/benchmarks/bench_scaling.py [P1] [--out PATH]`
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numba
import numpy as np
from bench_solver import median_seconds, monte_carlo_designs  # this folder's script (on sys.path when run)

from wrist_env import design
from wrist_env.builder.params import BuildParams
from wrist_env.participants.registry import load_model
from wrist_env.solver.drivers import idealized
from wrist_env.solver.simulate import prepare, simulate, simulate_batch

BATCHES = (1, 2, 4, 8, 16, 32, 64)
SPACINGS_MM = (0.7, 1.0, 1.4, 2.0)  # contact-sample spacing; 1.0 mm is the default build


def in_batches(model, designs, n, driver, prepared) -> None:
    """All `designs` through `simulate_batch`, n at a time (the same work at every batch size)."""
    for start in range(0, len(designs), n):
        simulate_batch(model, designs[start : start + n], driver, prepared=prepared)


def throughput(name: str, repeats: int = 3) -> dict[int, list[float]]:
    """Simulations per second per batch size (64 Monte Carlo designs, n at a time), per thread count
    (1, 2); the thread counts alternate within each repeat, so a drifting machine load hits both."""
    model = load_model(name)
    driver = idealized(model)
    prepared = prepare(model, mode=driver.mode)
    designs = monte_carlo_designs(max(BATCHES))
    available = numba.config.NUMBA_NUM_THREADS
    counts = (1, min(2, available))
    in_batches(model, designs[:2], 1, driver, prepared)  # compile
    seconds = {(n, t): [] for n in BATCHES for t in counts}
    for n in BATCHES:
        for _ in range(repeats):
            for t in counts:
                numba.set_num_threads(t)
                start = time.perf_counter()
                in_batches(model, designs, n, driver, prepared)
                seconds[n, t].append(time.perf_counter() - start)
    numba.set_num_threads(available)
    out = {t: [len(designs) / float(np.median(seconds[n, t])) for n in BATCHES] for t in counts}
    for t in counts:
        print(f"{t} thread(s): " + ", ".join(f"{n}: {r:.1f}/s" for n, r in zip(BATCHES, out[t])))
    return out


def resolution(name: str) -> list[tuple[float, int, int, float]]:
    """(spacing mm, samples, steps, seconds) of one population sweep per contact-sample spacing, one thread."""
    numba.set_num_threads(1)
    rows = []
    for spacing in SPACINGS_MM:
        model = load_model(name, BuildParams(contact_spacing_mm=spacing))
        driver = idealized(model)
        prepared = prepare(model, mode=driver.mode)
        result = simulate(model, design.population(), driver, prepared=prepared)
        seconds = median_seconds(lambda: simulate(model, design.population(), driver, prepared=prepared))
        rows.append((spacing, len(model.sample_points), int(result.steps.sum()), seconds))
        steps = rows[-1][2]
        print(
            f"spacing {spacing:.1f} mm: {rows[-1][1]} samples, {steps} steps, {1e3 * seconds:.1f} ms, "
            f"{1e6 * seconds / steps:.1f} µs/step"
        )
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return rows


def figure(name: str, rates: dict[int, list[float]], rows, out: str) -> None:
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for threads, r in rates.items():
        left.plot(BATCHES, r, "o-", label=f"{threads} thread{'s' if threads > 1 else ''}")
    left.set_xscale("log", base=2)
    left.set_xlabel("designs per batch")
    left.set_ylabel("idealized sweeps per second")
    left.set_title(f"{name}: 64 Monte Carlo sweeps, n per batch")
    left.legend()
    left.grid(alpha=0.3)
    samples = [r[1] for r in rows]
    per_step = [1e6 * r[3] / r[2] for r in rows]
    right.plot(samples, [1e3 * r[3] for r in rows], "o-", label="ms per sweep")
    right.plot(samples, per_step, "s--", label="µs per step")
    for (spacing, n, _, _), y in zip(rows, per_step):
        right.annotate(f"{spacing:g} mm", (n, y), textcoords="offset points", xytext=(4, 6), fontsize=8)
    right.set_xlabel("contact samples (spacing labelled)")
    right.set_ylabel("one thread")
    right.set_title(f"{name}: cost against contact resolution")
    right.legend()
    right.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"figure: {out}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("name", nargs="?", default="P1")
    parser.add_argument("--out", default=None, help="figure path (default runs/figures/scaling_<name>.png)")
    args = parser.parse_args(argv)
    rates = throughput(args.name)
    ratio = rates[max(rates)][-1] / rates[1][-1]
    print(f"2 threads / 1 thread at {BATCHES[-1]} designs: {ratio:.2f}×")
    rows = resolution(args.name)
    out = Path(args.out or f"runs/figures/scaling_{args.name}.png")
    out.parent.mkdir(parents=True, exist_ok=True)
    figure(args.name, rates, rows, str(out))


if __name__ == "__main__":
    main()
