"""How close the explicit solver's answers are to converged ones (issue 13's accuracy yardstick).

For each participant and motion (the idealized sweep, the 15-frame calibration
trial), the population design and N Monte Carlo designs (Table 2 normals at
±3 SD, each injurable ligament torn with probability 0.3) are simulated with
the solver settings under test and with a reference (half the time step, a 10×
tighter equilibrium tolerance, 8× longer holds). Printed per motion: steps per
simulation, frames that ran out of hold steps, and the largest centre-of-mass
distance (mm) and rotation (°) of a moving bone from the reference — median,
95th percentile, maximum, and the share of designs within 0.1 mm and 0.5°.
Because a soft design can reach different equilibria by different paths, the
reference is run twice more along other paths (a quarter of the diagonal mass's time
step, and ramps twice as slow): a design whose three converged runs agree
within 0.1 mm and 0.5° is path-independent, and the share within is printed
for those designs too (for the others no run has a converged answer to match).
With --newton K, the population design and the first K−1 Monte Carlo designs
are also polished by the quasi-static Newton reference
(`wrist_env.solver.equilibrium.nearest`): the distance from each explicit
answer to the equilibrium nearest it, and the net force left there.

With --frame-local, instead: each frame of each path-independent design run alone from the
reference's previous frame, by the settings under test and by the diagonal mass (`frame_local`).

Run: `python experiments/verification/solver_accuracy.py [P1 P2 P3] [--designs 100] [--newton 3] [--diagonal] [--frame-local] [--set dt_s=9e-5 ...]`
(--set changes the settings under test; the reference stays the diagonal mass's (`BASELINE`), with the same
`smooth_normals`, which changes the answer, not only the path to it).
References are cached in runs/solver_accuracy/ under a hash of their settings.
The three reference runs take ~1 min per participant for 100 designs on 2 cores (measured at ee125c8).
"""

from __future__ import annotations

import argparse
import ast
import hashlib
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from bench_solver import monte_carlo_designs  # noqa: E402  (experiments/benchmarks/bench_solver.py)

from wrist_env import design
from wrist_env.participants import registry
from wrist_env.participants.registry import load_model
from wrist_env.solver.drivers import idealized, trial_driver
from wrist_env.solver.equilibrium import distance, nearest
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import prepare, simulate_batch, simulate_frame

CACHE = Path(__file__).resolve().parents[2] / "runs" / "solver_accuracy"  # the repository root's runs/, git-ignored
TOLERANCE = (0.1, 0.5)  # mm, degrees: issue 13's "answer unchanged"
BASELINE = SolverSettings().diagonal()
"""The yardstick's base: the diagonal mass (the default until issue 52). The reference runs are built on it,
and the settings under test are compared with it on the same designs."""


def reference_settings(base: SolverSettings) -> SolverSettings:
    """Half the time step, a 10× tighter tolerance and force floor, 8× longer holds."""
    s = base.halved()
    return replace(
        s, tolerance=s.tolerance / 10, force_floor_n=s.force_floor_n / 10, max_hold_steps=8 * s.max_hold_steps
    )


def path_settings(reference: SolverSettings) -> dict[str, SolverSettings]:
    """Two more converged runs along other paths: half the reference's step (tolerance and holds kept,
    so twice the hold steps) and ramps twice as slow."""
    quarter = replace(reference.halved(), max_hold_steps=2 * reference.max_hold_steps)
    return {"quarter": quarter, "slow": replace(reference, ramp_steps=2 * reference.ramp_steps)}


def largest_distance(a: np.ndarray, b: np.ndarray, com0: np.ndarray) -> tuple[float, float]:
    """Largest centre-of-mass distance (mm) and rotation (deg) of a moving bone over the frames."""
    d = distance(a, b, com0).max(axis=0)
    return float(d[0]), float(d[1])


def drivers(name: str, model):
    return {
        "sweep": idealized(model),
        "trial": trial_driver(model, registry.trial(name, "calibrate")),
    }


def reference(name: str, model, designs, base: SolverSettings) -> dict[str, np.ndarray]:
    """Poses and success of the reference runs: "<motion>" and "<motion>_ok" (the reference), and the
    same with "_quarter" and "_slow" (`path_settings`)."""
    settings = reference_settings(base)
    key = hashlib.sha1(repr(settings).encode()).hexdigest()[:8]  # a new default gets a new reference
    path = CACHE / f"{name}_{len(designs) - 1}_{key}_paths.npz"
    if path.exists():
        cached = dict(np.load(path))
        if all(f"{motion}_nodes" in cached for motion in ("sweep", "trial")):
            return cached
    out = {}
    runs_of = {"": settings} | {f"_{k}": s for k, s in path_settings(settings).items()}
    for motion, driver in drivers(name, model).items():
        for suffix, s in runs_of.items():
            runs = simulate_batch(model, designs, driver, s)
            out[motion + suffix] = np.stack([r.poses for r in runs])
            out[motion + suffix + "_ok"] = np.array([r.ok for r in runs])
            if not suffix:  # the membrane's nodes too: a frame-local run starts from the reference's state
                out[motion + "_nodes"] = np.stack([r.membrane_nodes for r in runs])
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, **out)
    return out


def path_independent(ref: dict[str, np.ndarray], motion: str, com: np.ndarray) -> np.ndarray:
    """Which designs' three converged runs (reference, quarter step, slow ramps) all succeed and agree
    within `TOLERANCE`."""
    out = []
    for i in range(len(ref[motion])):
        ok = all(ref[f"{motion}{s}_ok"][i] for s in ("", "_quarter", "_slow"))
        out.append(ok and all(within(ref[motion][i], ref[f"{motion}{s}"][i], com) for s in ("_quarter", "_slow")))
    return np.array(out)


def within(a: np.ndarray, b: np.ndarray, com: np.ndarray) -> bool:
    """Every moving bone of runs a and b within `TOLERANCE` at every frame."""
    d = largest_distance(a, b, com)
    return d[0] <= TOLERANCE[0] and d[1] <= TOLERANCE[1]


def mcnemar(a: list[bool], b: list[bool]) -> str:
    """The paired comparison of two solvers' hits on the same designs: the discordant counts and the
    exact McNemar p (two-sided binomial test of the discordant pairs)."""
    from scipy.stats import binomtest

    only_a = sum(x and not y for x, y in zip(a, b))
    only_b = sum(y and not x for x, y in zip(a, b))
    p = binomtest(only_a, only_a + only_b).pvalue if only_a + only_b else 1.0
    return (
        f"within for the diagonal mass only {only_a}, for the settings under test only {only_b} (McNemar p = {p:.2g})"
    )


def report(name: str, n_designs: int, settings: SolverSettings, n_newton: int, paired: bool = False) -> None:
    model = load_model(name)
    designs = [design.population()] + monte_carlo_designs(n_designs)
    ref = reference(name, model, designs, replace(BASELINE, smooth_normals=settings.smooth_normals))
    for motion, driver in drivers(name, model).items():
        runs = simulate_batch(model, designs, driver, settings)
        both = [i for i, r in enumerate(runs) if r.ok and ref[motion + "_ok"][i]]
        d = np.array([largest_distance(runs[i].poses, ref[motion][i], model.com) for i in both])
        steps = np.array([r.steps.sum() for r in runs])
        capped_frames = [int(np.sum(r.steps[1:] >= settings.ramp_steps + settings.max_hold_steps)) for r in runs]
        capped = sum(capped_frames)
        settled = np.array([capped_frames[i] == 0 for i in both])
        close = (d[:, 0] <= TOLERANCE[0]) & (d[:, 1] <= TOLERANCE[1])
        share_within = close.mean()
        frames = sum(len(r.steps) - 1 for r in runs)
        independent = path_independent(ref, motion, model.com)
        matched = [runs[i].ok and within(runs[i].poses, ref[motion][i], model.com) for i in np.flatnonzero(independent)]
        pop = largest_distance(runs[0].poses, ref[motion][0], model.com)
        print(
            f"{name} {motion}: {steps[0]} steps (population), {steps.mean():.0f} mean; "
            f"{capped}/{frames} frames ran out of hold steps; failed {sum(not r.ok for r in runs)} "
            f"(reference {int((~ref[motion + '_ok']).sum())})\n"
            f"  from the reference: population {pop[0]:.3f} mm {pop[1]:.2f}°; designs median "
            f"{np.median(d[:, 0]):.3f} mm {np.median(d[:, 1]):.2f}°, 95th pct {np.percentile(d[:, 0], 95):.3f} mm "
            f"{np.percentile(d[:, 1], 95):.2f}°, max {d[:, 0].max():.3f} mm {d[:, 1].max():.2f}°; "
            f"within 0.1 mm and 0.5°: {100 * share_within:.0f} %\n"
            f"  designs with every frame settled: {100 * np.mean(close[settled]):.0f} % of {settled.sum()} within; "
            f"with a frame out of hold steps: {100 * np.mean(close[~settled]) if (~settled).any() else 0:.0f} % "
            f"of {(~settled).sum()}\n"
            f"  path-independent designs (reference, quarter step and slow ramps agree): {independent.sum()} of "
            f"{len(independent)}; of them within 0.1 mm and 0.5°: {100 * np.mean(matched):.0f} %"
        )
        if paired:  # the diagonal mass on the same designs
            defaults = simulate_batch(model, designs, driver, replace(BASELINE, smooth_normals=settings.smooth_normals))
            hits = [
                defaults[i].ok and within(defaults[i].poses, ref[motion][i], model.com)
                for i in np.flatnonzero(independent)
            ]
            d_steps = np.mean([r.steps.sum() for r in defaults])
            print(
                f"  the diagonal mass: {d_steps:.0f} mean steps ({d_steps / steps.mean():.2f}× the settings under test); "
                f"path-independent within {100 * np.mean(hits):.0f} %; {mcnemar(hits, matched)}"
            )
        for i in tqdm(range(min(n_newton, len(runs))), desc=f"{name} {motion} Newton", leave=False):
            if not runs[i].ok:
                continue
            eq = nearest(model, designs[i], driver, runs[i], settings)
            label = "population" if i == 0 else f"design {i}"
            tqdm.write(
                f"  Newton, {label}: explicit answer {eq.distance[:, 0].max():.3f} mm {eq.distance[:, 1].max():.2f}° "
                f"from its nearest equilibrium; net force left {eq.residual[:, 0].max():.2g} N "
                f"(explicit {runs[i].residual[:, 0].max():.2g} N)"
            )


def frame_local(name: str, n_designs: int, settings: SolverSettings) -> None:
    """Each frame of each path-independent design run alone from the reference's previous frame
    (`simulate.simulate_frame`), by the settings under test and by the diagonal mass: the share of frames
    that land within `TOLERANCE` (and within 0.02 mm and 0.1°) of the reference's, the McNemar test on
    the frames, and the mean steps per frame. A solver's error at a frame, apart from the path that led
    there."""
    model = load_model(name)
    designs = [design.population()] + monte_carlo_designs(n_designs)
    ref = reference(name, model, designs, replace(BASELINE, smooth_normals=settings.smooth_normals))
    defaults = replace(BASELINE, smooth_normals=settings.smooth_normals)
    for motion, driver in drivers(name, model).items():
        chosen = np.flatnonzero(path_independent(ref, motion, model.com))
        prepared = {k: prepare(model, s, driver.mode) for k, s in (("test", settings), ("defaults", defaults))}
        hits = {k: [] for k in prepared}
        close = {k: [] for k in prepared}
        steps = {k: [] for k in prepared}
        for i in tqdm(chosen, desc=f"{name} {motion} frame-local", leave=False):
            for f in range(1, driver.n_frames):
                target = ref[motion][i][f]
                for k, p in prepared.items():
                    r = simulate_frame(
                        model,
                        designs[i],
                        driver,
                        f,
                        ref[motion][i][f - 1],
                        ref[motion + "_nodes"][i][f - 1],
                        prepared=p,
                    )
                    d = distance(r.poses[1:], target[None], model.com)[0] if r.ok else (np.inf, np.inf)
                    hits[k].append(bool(d[0] <= TOLERANCE[0] and d[1] <= TOLERANCE[1]))
                    close[k].append(bool(d[0] <= 0.02 and d[1] <= 0.1))
                    steps[k].append(int(r.steps[1]))
        print(
            f"{name} {motion} frame-local ({len(hits['test'])} frames of {len(chosen)} path-independent designs): "
            f"within 0.1 mm and 0.5° — settings under test {100 * np.mean(hits['test']):.1f} %, diagonal mass "
            f"{100 * np.mean(hits['defaults']):.1f} %; within 0.02 mm and 0.1° — {100 * np.mean(close['test']):.1f} % / "
            f"{100 * np.mean(close['defaults']):.1f} %; steps per frame {np.mean(steps['test']):.0f} / "
            f"{np.mean(steps['defaults']):.0f}\n  {mcnemar(hits['defaults'], hits['test'])}"
        )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("participants", nargs="*", default=["P1", "P2", "P3"])
    parser.add_argument("--designs", type=int, default=100, help="Monte Carlo designs besides the population's")
    parser.add_argument("--newton", type=int, default=3, help="designs polished by the Newton reference")
    parser.add_argument("--set", nargs="*", default=[], metavar="FIELD=VALUE", help="settings under test")
    parser.add_argument(
        "--diagonal",
        action="store_true",
        help="test SolverSettings().diagonal() instead of the defaults (the block mass)",
    )
    parser.add_argument(
        "--frame-local",
        action="store_true",
        help="only the frame-local comparison (`frame_local`), against the diagonal mass",
    )
    args = parser.parse_args(argv)
    changes = {k: ast.literal_eval(v) for k, v in (item.split("=", 1) for item in args.set)}
    base = BASELINE if args.diagonal else SolverSettings()
    settings = replace(base, **changes)
    under = ("the diagonal mass" if args.diagonal else "the defaults (the block mass)") + (
        f" with {changes}" if changes else ""
    )
    print(f"settings under test: {under}; reference: {reference_settings(BASELINE)}")
    for name in args.participants:
        if args.frame_local:
            frame_local(name, args.designs, settings)
            continue
        report(name, args.designs, settings, args.newton, paired=not args.diagonal or bool(changes))


if __name__ == "__main__":
    main()
