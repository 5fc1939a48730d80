"""Benchmark: what one explicit step spends its time on, phase by phase, for both solvers.

At a settled frame of the participant's calibration trial (frame 8 of the population design's
default run: the bones in contact, the ligaments taut), each phase of `step.explicit_step` is called
`--repeats` times in a compiled loop at that state and timed (median of 5 loops, µs per call):
- the force pass (`step.net_forces`: contact, fibres, the RSC membrane, the driver's lines), and
  its three parts alone (`contact_forces`, `fibre_forces`, `membrane_forces`);
- the block mass's rebuild (`tangent.tangent` + `preconditioner.block_mass`), done every
  block_refresh_steps steps and at each stage;
- the membrane's substeps (`membrane.substep`, membrane_substeps passes a step);
- the update (`integrator.move_diagonal` or `move_blocks`).
Beside them, a whole simulation's µs per step (the trial, one core), so the phases' share shows. The
state does not move between calls, so the contact's active sets are never refilled here: a refill's
cost shows only in the whole step.

Run: `python experiments/benchmarks/bench_step_phases.py [P1]`. On a shared machine expect ±10 %.
"""

from __future__ import annotations

import sys
import time

import numpy as np
from numba import njit

from wrist_env import design
from wrist_env.participants import registry
from wrist_env.solver import step
from wrist_env.solver.drivers import trial_driver
from wrist_env.solver.forces import contact_forces, fibre_forces
from wrist_env.solver.integrator import move_blocks, move_diagonal
from wrist_env.solver.membrane import membrane_forces, new_scratch, substep
from wrist_env.solver.preconditioner import block_mass, metric
from wrist_env.solver.rigid import pose_state
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import prepare, simulate, stiffness
from wrist_env.solver.tangent import tangent

FRAME = 8
SOLVERS = {"diagonal mass": SolverSettings().diagonal(), "block mass (default)": SolverSettings()}


@njit(cache=True, error_model="numpy")
def _force_pass(n, state, work, system, design_arrays, load):
    for _ in range(n):
        step.net_forces(state, work, system, design_arrays, load, np.bool_(False), np.bool_(False), True)


@njit(cache=True, error_model="numpy")
def _contact(n, state, work, system):
    for _ in range(n):
        band = system.settings.active_band_mm
        contact_forces(state, system.bodies.com0, system.grids, system.law, work, band, np.bool_(False), True)


@njit(cache=True, error_model="numpy")
def _fibres(n, state, work, system, d):
    for _ in range(n):
        damping_s = system.settings.fibre_damping_s
        fibre_forces(state, system.bodies.com0, system.fibres, damping_s, d, work, np.bool_(False))


@njit(cache=True, error_model="numpy")
def _membrane(n, state, work, system, d):
    for _ in range(n):
        k = system.settings.membrane_contact_stiffness
        membrane_forces(state, system.bodies.com0, system.membrane, k, d, work, np.bool_(False), True)


@njit(cache=True, error_model="numpy")
def _rebuild(n, state, work, system, d, m):
    for _ in range(n):
        tangent(state, system, d, work, m, True)
        block_mass(state.R, system.bodies, system.settings, m)


@njit(cache=True, error_model="numpy")
def _substeps(n, state, system, d, scratch):
    for _ in range(n):
        substep(state, system, d, scratch, True)


@njit(cache=True, error_model="numpy")
def _update(n, state, work, system, m, blocks):
    moved = step.State(state.R.copy(), state.x.copy(), state.v.copy(), state.w.copy(), state.nodes, state.nv)
    for _ in range(n):
        if blocks:
            move_blocks(moved, work, system.settings, m)
        else:
            move_diagonal(moved, work, system.bodies, system.settings)


def median_us(fn, n: int) -> float:
    fn(1)
    times = []
    for _ in range(5):
        start = time.perf_counter()
        fn(n)
        times.append(time.perf_counter() - start)
    return float(np.median(times)) / n * 1e6


def phases(name: str, settings: SolverSettings, n: int) -> dict[str, float]:
    """µs per call of each phase at the settled trial frame, and a whole simulation's µs per step."""
    model = registry.load_model(name)
    driver = trial_driver(model, registry.trial(name, "calibrate"))
    pop = design.population()
    run = simulate(model, pop, driver)
    p = prepare(model, settings, driver.mode)
    d = stiffness(p, pop)
    R, x = pose_state(run.poses[FRAME], model.com)
    nodes = np.ascontiguousarray(run.membrane_nodes[FRAME])
    state = step.State(R, x, np.zeros_like(x), np.zeros_like(x), nodes, np.zeros_like(nodes))
    work = step.new_work(p.grids, nodes)
    body, point, direction, tension = driver.kernel_load()
    load = step.Load(body, point, direction, np.ascontiguousarray(tension[FRAME]))
    system = p.system
    step.net_forces(state, work, system, d, load, True, False, True)  # fill the active sets
    m = metric()
    out = {
        "force pass (net_forces)": median_us(lambda k: _force_pass(k, state, work, system, d, load), n),
        "  contact_forces": median_us(lambda k: _contact(k, state, work, system), n),
        "  fibre_forces": median_us(lambda k: _fibres(k, state, work, system, d), n),
        "  membrane_forces": median_us(lambda k: _membrane(k, state, work, system, d), n),
    }
    if settings.block_mass:
        out["block-mass rebuild (tangent + block_mass)"] = median_us(
            lambda k: _rebuild(k, state, work, system, d, m), n
        )
    if settings.membrane_substeps:
        scratch = new_scratch(nodes)
        out[f"membrane substeps ({settings.membrane_substeps} a step)"] = median_us(
            lambda k: _substeps(k, state._replace(nodes=nodes.copy()), system, d, scratch), n
        )
    step.net_forces(state, work, system, d, load, True, False, True)
    if settings.block_mass:
        _rebuild(1, state, work, system, d, m)
    out["update (move_blocks)" if settings.block_mass else "update (move_diagonal)"] = median_us(
        lambda k: _update(k, state, work, system, m, settings.block_mass), n
    )
    simulate(model, pop, driver, settings)
    times = []
    for _ in range(5):
        start = time.perf_counter()
        whole = simulate(model, pop, driver, settings)
        times.append(time.perf_counter() - start)
    out["whole simulation, per step"] = float(np.median(times)) / whole.steps.sum() * 1e6
    out["steps per simulation"] = float(whole.steps.sum())
    return out


def main(name: str = "P1", n: int = 2000) -> None:
    rows = {solver: phases(name, settings, n) for solver, settings in SOLVERS.items()}
    order = ("force", "  ", "block", "membrane substeps", "update", "whole", "steps")
    keys = sorted(
        dict.fromkeys(k for r in rows.values() for k in r),
        key=lambda k: next(i for i, o in enumerate(order) if k.startswith(o)),
    )
    print(f"| {name}, calibration trial frame {FRAME}, µs per call | " + " | ".join(SOLVERS) + " |")
    print("|---|" + "---|" * len(SOLVERS))
    for k in keys:
        cells = [rows[s].get(k) for s in SOLVERS]
        fmt = "{:,.0f}" if k.startswith("steps") else "{:.1f}"
        print(f"| {k} | " + " | ".join("" if c is None else fmt.format(c) for c in cells) + " |")


if __name__ == "__main__":
    main(*sys.argv[1:2])
