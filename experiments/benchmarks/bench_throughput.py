"""Benchmark: the default solver's simulations per second, this checkout against another, in turn.

For this checkout and, with `--against PATH`, another one (an older commit's worktree), in turn (A B A B
…, so a drift of the shared machine's speed hits both), each participant in a fresh Python process
running that checkout's default solver (`simulate(..., settings=None)`, whatever its defaults are) over
the same designs: 64 Monte Carlo designs (Table 2 normals truncated at ±3 SD, each injurable ligament
torn with probability 0.3, seed 0, as `bench_solver.py`) batched on every core (`simulate_batch`), and
the population design alone on one core (median of 5), for the idealized sweep (17 frames) and the
participant's 15-frame calibration trial, and what the trial rate makes of the default benchmark (3
participants × 5 instances × 11 calibrators × 300 evaluations, simulation time only). The kernels load from each checkout's warm Numba cache (a
warm-up simulation first). Prints each figure's median over the rounds and, with `--against`, the
ratio this / that; issue 52 asks the batched rates to reach 3× main's.

Run: `python experiments/benchmarks/bench_throughput.py [P1 P2 P3] [--against PATH] [--rounds 2] [--out FILE]`
(`--out`: also write the table, with both commits and the machine, as Markdown; the solver page of the
docs includes `docs/speed/throughput.md`). About a minute per participant and checkout a round; on a
shared machine expect ±15 %.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_cold_start import HERE, _run, median_rows, write_table  # noqa: E402  (experiments/benchmarks/bench_cold_start.py)

PROBE = """
import json, sys, time
import numpy as np
from wrist_env import design
from wrist_env import table2
from wrist_env.participants import registry
from wrist_env.solver.drivers import idealized, trial_driver
from wrist_env.solver.simulate import simulate, simulate_batch

name = sys.argv[1]
BENCHMARK = 3 * 11 * 5 * 300  # participants x calibrators x seeds x budget: `wrist-bench benchmark`'s defaults
model = registry.load_model(name)
rng = np.random.default_rng(0)
materials = table2.sample_materials(64, 0)
injury = np.where(rng.random((64, 5)) < 0.3, -0.5, 0.5)
designs = [design.from_action(np.r_[m, i]) for m, i in zip(materials, injury)]
pop = design.population()
out = {}
for motion, driver in (("sweep", idealized(model)), ("trial", trial_driver(model, registry.trial(name, "calibrate")))):
    simulate_batch(model, designs[:2], driver)
    times = []
    for _ in range(5):
        start = time.perf_counter()
        simulate(model, pop, driver)
        times.append(time.perf_counter() - start)
    out[f"{motion}: population design, one core, ms"] = 1e3 * float(np.median(times))
    start = time.perf_counter()
    results = simulate_batch(model, designs, driver)
    out[f"{motion}: 64 designs batched, simulations/s"] = len(designs) / (time.perf_counter() - start)
    out[f"{motion}: 64 designs batched, mean steps"] = float(np.mean([r.steps.sum() for r in results if r.ok]))
rate = out["trial: 64 designs batched, simulations/s"]
out["the default benchmark's 49,500 trial evaluations at that rate, min"] = BENCHMARK / rate / 60
print(json.dumps(out))
"""


def measure(tree: Path, participant: str) -> dict[str, float]:
    """The probe's figures for `participant` in a fresh process of the checkout at `tree` (its own Numba cache)."""
    key = hashlib.sha1(str(tree).encode()).hexdigest()[:8]
    cache = Path(tempfile.gettempdir()) / f"wrist-env-throughput-{key}"  # one warm cache per checkout, kept
    _, out = _run(tree, cache, ["-c", PROBE, participant])
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("participants", nargs="*", default=["P1", "P2", "P3"])
    p.add_argument("--against", type=Path, help="another checkout to compare with (e.g. a worktree of main)")
    p.add_argument("--rounds", type=int, default=2, help="runs of each checkout and participant, in turn (default 2)")
    p.add_argument("--out", type=Path, help="also write the table here (Markdown), with the commits and machine")
    args = p.parse_args()
    trees = {"this": HERE} | ({"against": args.against.resolve()} if args.against else {})
    for tree in trees.values():  # compile (or load) each checkout's kernels before any timing
        measure(tree, args.participants[0])
    runs = {(name, part): [] for name in trees for part in args.participants}
    for r in range(args.rounds):
        for part in args.participants:
            for name, tree in trees.items():
                runs[name, part].append(measure(tree, part))
                print(f"round {r + 1}/{args.rounds}, {part}, {name}: done", file=sys.stderr, flush=True)
    lines = [
        f"| participant, figure (median of {args.rounds}) | this |"
        + (" against | this / against |" if args.against else "")
    ]
    lines.append("|---|---|" + ("---|---|" if args.against else ""))
    for part in args.participants:
        lines += median_rows({name: runs[name, part] for name in trees}, f"{part}, ", ",.1f")
    print("\n".join(lines))
    if args.out:
        write_table(args.out, "bench_throughput.py", trees, lines)


if __name__ == "__main__":
    main()
