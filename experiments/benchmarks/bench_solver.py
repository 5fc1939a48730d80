"""Benchmark: the explicit solver's speed on a built participant (after compilation).

Prints, for P1 (or the participant named on the command line), for two solvers
side by side in one run — the diagonal mass (`SolverSettings().diagonal()`, the default until
issue 52) and the block mass (the defaults, `SolverSettings()`) — and their ratio:
- steps, µs per step and ms per simulation on one core: the idealized
  flexion–extension sweep (17 frames, ±40°) with the population design, and
  the participant's 15-frame calibration trial (the capitate's 6 DOF prescribed);
- simulations per second batched (`simulate_batch`, one thread per core) on all
  cores, for Monte Carlo designs (Table 2 normals truncated at ±3 SD, each
  injurable ligament torn with probability 0.3), their mean steps and share ok;
- what that makes of the Monte Carlo study (2 × 12,500 sweeps) and the full
  default benchmark's 49,500 trial evaluations (simulation time only);
- efficiency: the time of a bare loop doing only the signed-distance
  look-ups of one step (the samples within the active band at the settled
  neutral pose) over the time of a full step (which also refills the active
  sets, and does the ligaments, the membrane and the integration);
- the ratio to the preprint's 45 s per Abaqus simulation.

Run: `python experiments/benchmarks/bench_solver.py [P1] [--fossa-sweep F D] [--no-distal-row] [--no-fixed-ligaments]
[--load N]` (the flags pick an anatomy variant and the idealized load, as for `wrist-bench validate`).
Timings are medians of repeated runs on a shared machine; expect ±10 %.
"""

from __future__ import annotations

import time

import numpy as np
from numba import get_num_threads, njit

from wrist_env import design, table2
from wrist_env.participants import registry
from wrist_env.participants.registry import load_model
from wrist_env.solver import arrays
from wrist_env.solver.drivers import idealized, static, trial_driver
from wrist_env.solver.forces import pair_transform, rebuild_active, sample_lookup, sample_lookup_smooth
from wrist_env.solver.rigid import pose_state
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import simulate, simulate_batch

PREPRINT_SECONDS = 45.0  # one Abaqus simulation
PREPRINT_STUDY_DAYS = 13  # the preprint's Monte Carlo study


def median_seconds(fn, repeats: int = 9) -> float:
    fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def calibration_trial(name: str, model):
    """The participant's 15-frame calibration trial as a `Task` drives it: the capitate's 6 DOF
    prescribed, the radial column free under the lines at the trial's recorded load."""
    return trial_driver(model, registry.trial(name, "calibrate"))


def monte_carlo_designs(n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    materials = table2.sample_materials(n, seed)
    injury = np.where(rng.random((n, 5)) < 0.3, -0.5, 0.5)
    return [design.from_action(np.r_[m, i]) for m, i in zip(materials, injury)]


@njit(cache=True, error_model="numpy")
def _lookups(repeats, R, x, com0, grids, active, n_active, smooth):
    total = 0.0
    for _ in range(repeats):
        for p in range(grids.pair_bones.shape[0]):
            a, b = grids.pair_bones[p, 0], grids.pair_bones[p, 1]
            M = pair_transform(R, x, com0, a, b)
            start = grids.sample_offsets[p]
            for j in range(n_active[p]):
                s = active[start + j]
                if smooth:
                    d, gx, _, _, _, _, _ = sample_lookup_smooth(grids, b, M, s)
                else:
                    d, gx, _, _, _, _, _ = sample_lookup(grids, b, M, s)
                total += d + gx
    return total


@njit(cache=True, error_model="numpy")
def bare_lookups(repeats, R, x, com0, grids, active, n_active, smooth):
    """Only the signed-distance look-ups of `repeats` steps' active samples, as the solver does them
    (with `smooth`, the nodal-normal look-up; the flag passed as a constant, as the solver does);
    the sum keeps them live."""
    if smooth:
        return _lookups(repeats, R, x, com0, grids, active, n_active, True)
    return _lookups(repeats, R, x, com0, grids, active, n_active, False)


def efficiency(model, steps_per_sim: float, seconds_per_sim: float) -> tuple[float, float, int]:
    """(bare look-up µs per step, full µs per step, active samples) at the settled neutral pose."""
    s = SolverSettings()
    settled = simulate(model, design.population(), static(model, 2))
    pose = settled.poses[-1]
    R, x = pose_state(pose, model.com)
    grids = arrays.grids(model, s.smooth_normals)
    active = np.zeros(len(grids.points), np.int64)
    n_active = np.zeros(len(grids.pair_bones), np.int64)
    rebuild_active(R, x, model.com, grids, s.active_band_mm, active, n_active, np.zeros((len(grids.pair_bones), 12)))
    repeats = 2000
    per_step = (
        median_seconds(lambda: bare_lookups(repeats, R, x, model.com, grids, active, n_active, s.smooth_normals), 5)
        / repeats
    )
    return per_step * 1e6, seconds_per_sim / steps_per_sim * 1e6, int(n_active.sum())


DIAGONAL, BLOCK = "diagonal mass", "block mass (default)"
SOLVERS = {DIAGONAL: SolverSettings().diagonal(), BLOCK: SolverSettings()}
"""The two solvers compared side by side: the diagonal mass and the block mass (`preconditioner`), the default."""
MONTE_CARLO_RUNS = 2 * 12_500  # the preprint's study: 2 participants x 12,500 successful runs
BENCHMARK_EVALUATIONS = 49_500  # the full default benchmark's calibration-trial simulations (leaderboards/runs.csv)


def one_core(model, driver, settings) -> tuple[float, int]:
    """(median seconds, steps) of the population design's run."""
    pop = design.population()
    result = simulate(model, pop, driver, settings)
    if not result.ok:
        raise SystemExit(f"the population design's run failed ({result.message}); nothing to time")
    return median_seconds(lambda: simulate(model, pop, driver, settings)), int(result.steps.sum())


def batched(model, driver, settings, designs) -> tuple[float, float, float]:
    """(simulations per second on all cores, share ok, mean steps) of the Monte Carlo designs."""
    simulate_batch(model, designs[:2], driver, settings)
    start = time.perf_counter()
    results = simulate_batch(model, designs, driver, settings)
    rate = len(designs) / (time.perf_counter() - start)
    ok = [r for r in results if r.ok]
    return rate, len(ok) / len(results), float(np.mean([r.steps.sum() for r in ok]))


def main(name: str, params=None, load_n=None) -> None:
    model = load_model(name, params)
    motions = {
        "idealized sweep, 17 frames": idealized(model) if load_n is None else idealized(model, load_n=load_n),
        "15-frame trial": calibration_trial(name, model),
    }
    designs = monte_carlo_designs(64)
    rows = {}
    for motion, driver in motions.items():
        for solver, settings in SOLVERS.items():  # one after the other, each motion: the same machine state
            seconds, steps = one_core(model, driver, settings)
            rate, ok, mean_steps = batched(model, driver, settings, designs)
            rows[motion, solver] = (seconds, steps, rate, ok, mean_steps)
    print(f"| {name}, population design, one core | " + " | ".join(SOLVERS) + " | ratio |")
    print("|---|" + "---|" * (len(SOLVERS) + 1))
    for motion in motions:
        (s0, n0, r0, ok0, m0), (s1, n1, r1, ok1, m1) = (rows[motion, solver] for solver in SOLVERS)
        print(f"| {motion}: steps | {n0:,} | {n1:,} | {n0 / n1:.2f}× fewer |")
        print(f"| {motion}: µs per step | {s0 / n0 * 1e6:.1f} | {s1 / n1 * 1e6:.1f} | {s1 / n1 / (s0 / n0):.2f}× |")
        print(f"| {motion}: ms per simulation | {s0 * 1e3:.1f} | {s1 * 1e3:.1f} | {s0 / s1:.2f}× faster |")
        print(
            f"| {motion}: 64 Monte Carlo designs batched on {get_num_threads()} cores, simulations/s "
            f"(mean steps, share ok) | {r0:.1f} ({m0:,.0f}, {ok0:.0%}) | {r1:.1f} ({m1:,.0f}, {ok1:.0%}) | {r1 / r0:.2f}× |"
        )
    sweep, trial = motions
    for solver in SOLVERS:
        mc = MONTE_CARLO_RUNS / rows[sweep, solver][3] / rows[sweep, solver][2] / 60
        bench = BENCHMARK_EVALUATIONS / rows[trial, solver][2] / 60
        print(
            f"{solver}: the Monte Carlo study's {MONTE_CARLO_RUNS:,} sweeps simulate in ~{mc:.1f} min "
            f"({PREPRINT_STUDY_DAYS * 24 * 60 / mc:,.0f}× faster than its {PREPRINT_STUDY_DAYS} days); the benchmark's "
            f"{BENCHMARK_EVALUATIONS:,} trial evaluations in ~{bench:.1f} min (simulation only, at these rates)"
        )
    bare, full, n_active = efficiency(model, rows[sweep, DIAGONAL][1], rows[sweep, DIAGONAL][0])
    print(
        f"efficiency (diagonal mass): bare look-ups {bare:.1f} µs of a {full:.1f} µs step ({n_active} active samples) = {bare / full:.0%}"
    )
    print(
        f"vs the preprint's 45 s per simulation: {PREPRINT_SECONDS / rows[trial, BLOCK][0]:,.0f}× faster (trial, block mass)"
    )


if __name__ == "__main__":
    import argparse

    from wrist_env.builder.params import add_anatomy_arguments, anatomy_params

    cli = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    cli.add_argument("participant", nargs="?", default="P1")
    add_anatomy_arguments(cli)
    cli.add_argument("--load", type=float)
    args = cli.parse_args()
    main(args.participant, anatomy_params(args), args.load)
