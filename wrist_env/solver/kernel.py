"""The explicit time-stepping kernel: settle → move to the first pose → motion (Numba).

Semi-implicit Euler with implicit mass-proportional damping for a
quasi-static answer. The radius and ulna are fixed, the free bodies (`model.FREE`)
free in 6 DOF, the capitate driven (all 6 DOF prescribed, or, for the
loaded driver, rotations prescribed and translations free under its
loads), the RSC membrane's interior nodes free point masses; the driver's
loads are lines of action on the bodies (`drivers.Loads`).
The free bones' masses are their (scaled) physical ones or, with
`Settings.block_mass`, one block each from the tangent stiffness
(`preconditioner`): the answer is the same equilibrium, reached in fewer steps.

Read `run` → `_run`: per stage (settle, move, each frame) it stages the capitate's targets
(`_stage`, a `Stage`, or the secant predictor's state: `step.predicted_start`), holds (`_ramp_and_hold`,
which calls `step.explicit_step`, which calls `net_forces`), checks (`_failure`) and records the frame
(`_record`). `_run` and those it calls once per stage or step are inlined into the entry point: each separately
compiled layer over the force kernels made Numba optimize and emit their code once more (issue 52;
`experiments/benchmarks/bench_cold_start.py` times a cold first simulation). The entry points
(`run`, and `entry(settings)` for the other three) take the model's `arrays.System` flat, as they
take `Frames`; every kernel below reads it as one System and a design as one `Stiffness`.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from wrist_env.ligaments import ALL_LIGAMENT_NAMES, RSC_INDEX
from wrist_env.model import BONES, CAPITATE, FREE
from wrist_env.solver.arrays import LOADED, System
from wrist_env.solver.forces import (
    C_AREA,
    C_FORCE,
    C_PEAK,
    R_AREA,
    R_FORCE,
    R_MEAN,
    R_PEAK,
)
from wrist_env.solver.integrator import kinetic_energy
from wrist_env.solver.membrane import new_scratch
from wrist_env.solver.preconditioner import SOLVED, metric
from wrist_env.solver.predictor import capitate_move, history, record
from wrist_env.solver.rigid import copy_into, interpolate_pose, rotvec_between, smoothstep
from wrist_env.solver.step import Carry, Load, State, Target, explicit_step, net_forces, new_work, predicted_start
from wrist_env.solver.stopping import converged, displacement

N_BONES = len(BONES)
N_LIGAMENTS = len(ALL_LIGAMENT_NAMES)
RSC = RSC_INDEX
OK, FAILED_NAN, FAILED_DIVERGED = 0, 1, 2


Frames = namedtuple("Frames", ["rotation", "com", "tension", "body", "point", "direction"])
"""The capitate's targets per frame: rotation (n_frames, 3, 3), centre of mass (n_frames, 3) mm (for the
loaded driver only the start: the centre is free); the loads per frame, tension (n_frames, n_lines) N on
the lines (body, point, direction) of `Load` (flat: a parallel loop takes no nested tuples)."""
Outputs = namedtuple(
    "Outputs", ["poses", "contact", "bundle", "energy", "residual", "steps", "settled", "nodes", "status"]
)
"""What a run fills: poses (n_frames, n_bodies, 4, 4); contact (n_frames, n_pairs, 4) (`forces.CONTACT_FIELDS`);
bundle forces (n_frames, n_bundles) N; kinetic and internal energy (n_frames, 2) N·mm; largest net
force (N) and moment (N·mm) on the free bones (n_frames, 2); steps per frame (n_frames,); 1 where the
frame's hold ended in equilibrium, 0 where it ran out of hold steps (n_frames,); RSC membrane
node positions (n_frames, M, 3) mm; status (1,)."""

Stage = namedtuple("Stage", ["Ra", "xa", "la", "axis", "shift", "lb", "ramp", "most", "start"])
"""One stage's capitate motion (`_ramp_and_hold`): from rotation Ra (3, 3) and centre xa (3,) mm by the
rotation vector axis (3,) rad and the shift (3,) mm, the lines' tensions from la to lb (n_lines,) N, over
`ramp` steps, then a hold of at most `most` steps; start: the run's steps before the stage."""

SETTLE, MOVE = -2, -1
"""The stages before frame 0: settle with the capitate at its static pose, then move it to the first pose."""


@njit(cache=True, error_model="numpy")
def _stage(f, R0, x0, frame_R, frame_x, frame_load, st):
    """Capitate targets of stage f (`SETTLE`, `MOVE` or a frame): start and end rotation, centre (mm)
    and line tensions (n_lines,) N, ramp steps, most hold steps."""
    if f == SETTLE:
        return R0, x0, frame_load[0], R0, x0, frame_load[0], 0, st.settle_steps
    if f == MOVE:
        return R0, x0, frame_load[0], frame_R[0], frame_x[0], frame_load[0], st.move_steps, st.max_hold_steps
    a = max(f - 1, 0)
    ramp = st.ramp_steps if f > 0 else 0
    return frame_R[a], frame_x[a], frame_load[a], frame_R[f], frame_x[f], frame_load[f], ramp, st.max_hold_steps


@njit(cache=True, error_model="numpy", nogil=True)
def run(bod, grids, law, fib, mem, st, stiffness, frames, out, R, x, nodes, first):
    """Simulate one design (`Stiffness`) of the model whose `arrays.System` is (bod, grids, law, fib,
    mem, st) through the capitate's `Frames` from the state (R, x, nodes), its stages from `first`
    (`_run`): smooth contact normals, the scaled physical mass (`SolverSettings().diagonal()`).

    One compiled entry point serves single runs and batches alike (`simulate.simulate_batch` runs
    designs on threads: `nogil`); it takes the System flat, as it takes `Frames`. `entry(settings)`
    picks it or one of its three siblings, each compiled only when first used."""
    _run(System(bod, grids, law, fib, mem, st), stiffness, frames, out, R, x, nodes, first, True, False)


@njit(cache=True, error_model="numpy", nogil=True)
def run_preconditioned(bod, grids, law, fib, mem, st, stiffness, frames, out, R, x, nodes, first):
    """`run` with the block mass, the membrane's substeps and the predictor compiled in (each on where
    its setting says: the defaults, `SolverSettings()`)."""
    _run(System(bod, grids, law, fib, mem, st), stiffness, frames, out, R, x, nodes, first, True, True)


@njit(cache=True, error_model="numpy", nogil=True)
def run_trilinear(bod, grids, law, fib, mem, st, stiffness, frames, out, R, x, nodes, first):
    """`run` with the trilinear interpolant's own gradient as the contact normal
    (`SolverSettings(smooth_normals=False).diagonal()`)."""
    _run(System(bod, grids, law, fib, mem, st), stiffness, frames, out, R, x, nodes, first, False, False)


@njit(cache=True, error_model="numpy", nogil=True)
def run_trilinear_preconditioned(bod, grids, law, fib, mem, st, stiffness, frames, out, R, x, nodes, first):
    """`run_preconditioned` with the trilinear interpolant's own gradient as the contact normal."""
    _run(System(bod, grids, law, fib, mem, st), stiffness, frames, out, R, x, nodes, first, False, True)


def entry(settings):
    """The compiled entry point for kernel `Settings`: smooth normals or not, the preconditioner's parts
    (block mass, membrane substeps, predictor) compiled in or not."""
    preconditioned = bool(settings.block_mass or settings.membrane_substeps > 0 or settings.predict)
    if settings.smooth_normals:
        return run_preconditioned if preconditioned else run
    return run_trilinear_preconditioned if preconditioned else run_trilinear


@njit(cache=True, error_model="numpy", inline="always")
def _run(system, stiffness, frames, out, R, x, nodes, first, smooth, preconditioned):
    """Simulate one design (`Stiffness`) of the model whose `arrays.System` is (bod, grids, law, fib,
    mem, st) through the capitate's `Frames` from the state (R (n_bodies, 3, 3), centres of mass x (n_bodies, 3) mm,
    membrane nodes (M, 3) mm; all overwritten), its stages from `first`: `SETTLE` from rest, or 1 from
    a frame-0 state (frame 0's outputs then left unfilled). Fills `out` (`Outputs`) and out.status[0]
    (0 ok, 1 NaN, 2 diverged). Steps per frame count those since the previous frame (frame 0: settling
    and the move included). Per stage: stage (its capitate targets, from the predictor's state if that
    is closer) → hold (`_ramp_and_hold`: ramp the capitate, then hold until `converged`, at least
    min_hold_steps, at most max_hold_steps; settling at most settle_steps) → check (`_failure`) →
    record (`_record`).

    `smooth` (`Settings.smooth_normals`) and `preconditioned` are compile-time constants: the contact
    loops are compiled for one kind of normal (read at run time in the inner loop, the flag cost a step
    1.4×), and the preconditioner's parts only where they can run (they are half a cold compile).
    Inlined into the entry points (`entry`)."""
    st = system.settings
    frame_R, frame_x, frame_load, body, point, direction = frames
    status = out.status
    n_frames = frame_R.shape[0]
    state = State(R, x, np.zeros((N_BONES, 3)), np.zeros((N_BONES, 3)), nodes, np.zeros_like(nodes))
    work = new_work(system.grids, nodes)
    status[0] = OK
    step = 0
    R0 = np.eye(3)
    x0 = system.bodies.com0[CAPITATE].copy()
    fire = np.array([st.fire_alpha0, 0.0, 0.0])
    load = Load(body, point, direction, np.zeros(frame_load.shape[1]))
    carry = Carry(fire, metric(), new_scratch(nodes))
    hist = history(N_BONES, nodes)
    taken = 0
    for f in range(first, n_frames):
        Ra, xa, la, Rb, xb, lb, ramp, most = _stage(f, R0, x0, frame_R, frame_x, frame_load, st)
        at_end = Load(body, point, direction, lb)  # the loads at the stage's end
        axis = rotvec_between(Rb, Ra)
        shift = xb - xa
        move = capitate_move(axis, shift)
        if preconditioned:
            if (
                st.predict
                and st.driver == LOADED
                and f > 0
                and predicted_start(state, work, system, stiffness, hist, Target(Rb, xb, at_end), move, smooth)
            ):
                ramp = st.predict_ramp_steps
                fire[0], fire[1], fire[2] = st.fire_alpha0, 0.0, 1.0
        stage = Stage(Ra, xa, la, axis, shift, lb, ramp, most, step)
        k, settled = _ramp_and_hold(state, work, system, stiffness, stage, load, carry, smooth, preconditioned)
        step += k
        taken += k
        status[0] = _failure(state.R, state.x, system.bodies.com0, st)
        if status[0] != OK:
            return
        if f < 0:  # SETTLE and MOVE have no output frame
            continue
        if preconditioned:
            if st.predict:
                record(hist, R, x, nodes, move)
        _record(f, state, work, system, stiffness, at_end, carry.metric, out, taken, settled, smooth, preconditioned)
        taken = 0


@njit(cache=True, error_model="numpy", inline="always")
def _ramp_and_hold(state, work, system, stiffness, stage, load, carry, smooth, preconditioned):
    """One stage's steps (`Stage`): the capitate ramps from (Ra, xa) by the rotation vector `axis` and
    `shift` (mm), the lines' tensions from la to lb (N; written into load.tension, `Load`), over `ramp`
    steps, then holds until `converged` (after at least min_hold_steps, at most `most`); stage.start the
    run's steps before it; `carry` what the steps carry (`step.Carry`). Returns the steps taken and
    whether the hold ended in equilibrium."""
    st = system.settings
    Ra, xa, la, axis, shift, lb, ramp, most, step = stage
    fire = carry.fire
    capR = np.eye(3)
    k = 0
    while k < ramp + most:
        s = smoothstep((k + 1) / ramp) if ramp > 0 else 1.0
        capx = interpolate_pose(Ra, xa, axis, capR, shift, s)
        for i in range(la.shape[0]):
            load.tension[i] = la[i] + s * (lb[i] - la[i])
        refresh = k % st.block_refresh_steps == 0 or (st.block_refresh_restart and fire[2] > 0.0)
        fire[2] = 0.0
        target = Target(capR, capx, load)
        explicit_step(state, work, system, stiffness, target, step + k, refresh, carry, smooth, preconditioned)
        k += 1
        if k >= ramp + st.min_hold_steps and converged(work.F, work.T, work.bundle, st):
            return k, True
    return k, False


@njit(cache=True, error_model="numpy", inline="always")
def _failure(R, x, com0, st):
    """The run's status at this state: `FAILED_NAN` if a solved body's centre is not finite,
    `FAILED_DIVERGED` if a free bone dislocated (`displacement` beyond max_disp_mm, or turned beyond
    max_rot_rad from the capitate), else `OK`."""
    for b in SOLVED:
        for i in range(3):
            if not np.isfinite(x[b, i]):
                return FAILED_NAN
    status = OK
    for b in FREE:
        if displacement(R, x, com0, b) > st.max_disp_mm:
            status = FAILED_DIVERGED
        rel = rotvec_between(R[b], R[CAPITATE])
        if np.sqrt(rel[0] ** 2 + rel[1] ** 2 + rel[2] ** 2) > st.max_rot_rad:
            status = FAILED_DIVERGED
    return status


@njit(cache=True, error_model="numpy", inline="always")
def _record(f, state, work, system, stiffness, load, m, out, taken, settled, smooth, preconditioned):
    """Fill frame f of `out` at the state reached (the last step's forces were those before it, so they
    are evaluated again here under the stage's end `load`); `taken` steps since the previous frame."""
    bod, st = system.bodies, system.settings
    R, x, nodes = state.R, state.x, state.nodes
    F, T, stats = work.F, work.T, work.stats
    com0 = bod.com0
    energy = net_forces(state, work, system, stiffness, load, np.bool_(False), np.bool_(True), smooth)
    poses = out.poses
    for b in range(N_BONES):
        for i in range(3):
            t = x[b, i]
            for j in range(3):
                poses[f, b, i, j] = R[b, i, j]
                t -= R[b, i, j] * com0[b, j]
            poses[f, b, i, 3] = t
            poses[f, b, 3, i] = 0.0
        poses[f, b, 3, 3] = 1.0
    contact = out.contact
    for p in range(stats.shape[0]):
        area = stats[p, C_AREA]
        contact[f, p, R_MEAN] = stats[p, C_FORCE] / area if area > 0 else 0.0
        contact[f, p, R_PEAK] = stats[p, C_PEAK]
        contact[f, p, R_AREA] = area
        contact[f, p, R_FORCE] = stats[p, C_FORCE]
    copy_into(out.bundle[f], work.bundle)
    out.energy[f, 0] = kinetic_energy(state, bod, st, stiffness.node_mass, m, preconditioned)
    out.energy[f, 1] = energy
    out.residual[f, 0] = 0.0
    out.residual[f, 1] = 0.0
    for b in FREE:
        out.residual[f, 0] = max(out.residual[f, 0], np.sqrt(F[b, 0] ** 2 + F[b, 1] ** 2 + F[b, 2] ** 2))
        out.residual[f, 1] = max(out.residual[f, 1], np.sqrt(T[b, 0] ** 2 + T[b, 1] ** 2 + T[b, 2] ** 2))
    out.steps[f] = taken
    out.settled[f] = 1 if settled else 0
    copy_into(out.nodes[f], nodes)
