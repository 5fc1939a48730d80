"""One explicit step of the solver (Numba): the forces at a state (`net_forces`), the step that moves the free
bodies under them (`explicit_step`), the secant predictor's start of a stage (`predicted_start`), and the
state, scratch, design, load, target and carried tuples they read (`State`, `Work`, `Stiffness`, `Load`,
`Target`, `Carry`). `kernel` runs them stage by stage; `equilibrium` and `outputs` call `net_forces` alone.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from wrist_env.ligaments import ALL_LIGAMENT_NAMES, RSC_INDEX
from wrist_env.model import BONES, CAPITATE, FREE
from wrist_env.solver.arrays import EXPERIMENTAL
from wrist_env.solver.forces import apply_force, contact_forces, fibre_forces, joint_forces, to_world
from wrist_env.solver.integrator import fire_step, move_blocks, move_diagonal
from wrist_env.solver.membrane import membrane_forces, place_nodes, substep
from wrist_env.solver.preconditioner import block_mass
from wrist_env.solver.predictor import predict
from wrist_env.solver.rigid import copy_into, orthonormalize
from wrist_env.solver.stopping import residual
from wrist_env.solver.tangent import tangent

N_BONES = len(BONES)
N_LIGAMENTS = len(ALL_LIGAMENT_NAMES)
RSC = RSC_INDEX


@njit(cache=True, error_model="numpy")
def net_forces(state, work, system, stiffness, load, rebuild, want_energy, smooth):
    """Forces F (N), torques T (N·mm), contact stats and bundle forces (all in `work`) at `state`
    (`State`) of `system` (`arrays.System`) under a design's `stiffness` and the driver's `load`; with
    `rebuild`, every pair's active contact samples are refilled first (otherwise a pair refills when
    its samples may have moved half the band); returns internal energy (N·mm; 0 unless `want_energy`)."""
    R, x, nodes = state.R, state.x, state.nodes
    F, T, bundle = work.F, work.T, work.bundle
    com0 = system.bodies.com0
    if rebuild:
        work.ref[:] = np.nan
    place_nodes(R, x, com0, system.membrane, nodes)
    F[:] = 0.0
    T[:] = 0.0
    bundle[:] = 0.0
    st, mem = system.settings, system.membrane
    # each force kernel takes the parts of the System it reads (a whole System's fields cost a call)
    energy = contact_forces(state, com0, system.grids, system.law, work, st.active_band_mm, want_energy, smooth)
    energy += fibre_forces(state, com0, system.fibres, st.fibre_damping_s, stiffness, work, want_energy)
    energy += joint_forces(state, system.bodies, work, want_energy)
    k_mem = st.membrane_contact_stiffness
    e_mem, rsc = membrane_forces(state, com0, mem, k_mem, stiffness, work, want_energy, smooth)
    energy += e_mem
    bundle[RSC] += rsc
    tension = load.tension
    for i in range(tension.shape[0]):  # the driver's lines of action (`Load`)
        if tension[i] != 0.0:
            b = load.body[i]
            p, u = load.point[i], load.direction[i]
            at = to_world(R, x, com0, b, p[0], p[1], p[2])
            apply_force(F, T, x, b, (tension[i] * u[0], tension[i] * u[1], tension[i] * u[2]), at)
    return energy


@njit(cache=True, error_model="numpy", inline="always")
def explicit_step(state, work, system, stiffness, target, step_index, refresh, carry, smooth, preconditioned):
    """One explicit step, the `step_index`-th of the run, with the capitate at `target` (`Target`: its
    rotation and centre, or, for the loaded driver, its rotation; the driver's lines at this step's
    tensions); with st.block_mass and `refresh`, the block mass carry.metric (`preconditioner.Metric`) is
    rebuilt at this state first; FIRE's state is carry.fire; with st.membrane_substeps the membrane's free
    nodes then take that many more steps of their own (`membrane.substep`; carry.substeps its arrays)."""
    bod, mem, st = system.bodies, system.membrane, system.settings
    R, x, v, w, nodes, nv = state
    node_force = work.node_force
    m = carry.metric
    copy_into(R[CAPITATE], target.rotation)
    if st.driver == EXPERIMENTAL:
        x[CAPITATE, 0], x[CAPITATE, 1], x[CAPITATE, 2] = target.centre
        v[CAPITATE] = 0.0
    w[CAPITATE] = 0.0
    net_forces(state, work, system, stiffness, target.load, np.bool_(False), np.bool_(False), smooth)
    blocks = False
    if preconditioned:  # a compile-time constant: see `_run`
        blocks = st.block_mass
        if blocks and refresh:
            tangent(state, system, stiffness, work, m, smooth)
            block_mass(R, bod, st, m)
    if st.fire_alpha0 > 0.0:
        fire_step(state, work, st, carry.fire, m, preconditioned)
    dt = st.dt
    lin = 1.0 / (1.0 + st.damping * dt)
    if blocks:
        move_blocks(state, work, st, m)
    else:
        move_diagonal(state, work, bod, st)
    if stiffness.node_mass > 0.0:
        for i in range(nodes.shape[0]):
            if mem.bone[i] < 0:
                for k in range(3):
                    nv[i, k] = (nv[i, k] + dt / stiffness.node_mass * node_force[i, k]) * lin
                    nodes[i, k] += dt * nv[i, k]
        if preconditioned:
            if st.membrane_substeps > 0:
                place_nodes(R, x, bod.com0, mem, nodes)
                substep(state, system, stiffness, carry.substeps, smooth)
    if step_index % 100 == 0:
        for b in FREE:
            orthonormalize(R[b])


@njit(cache=True, error_model="numpy")
def predicted_start(state, work, system, stiffness, hist, target, move, smooth):
    """Start the next stage, whose end puts the capitate and its lines at `target` (`Target`), from the
    secant predictor's state (`predictor.predict`, from `History` hist; `move` the stage's capitate move,
    mm) if the free bodies' residual there, with the capitate already at that pose, is below their
    residual left where they are; True if so (the state is the prediction), False if not (the positions
    are restored; the velocities, ~0 at the end of a hold, stay zeroed)."""
    mem, st = system.membrane, system.settings
    R, x, nodes = state.R, state.x, state.nodes
    keep_R, keep_x, keep_nodes = R.copy(), x.copy(), nodes.copy()
    copy_into(R[CAPITATE], target.rotation)
    if st.driver == EXPERIMENTAL:
        copy_into(x[CAPITATE], target.centre)
    load = target.load
    net_forces(state, work, system, stiffness, load, np.bool_(False), np.bool_(False), smooth)
    before = residual(work.F, work.T, st)
    if not predict(hist, state, mem, st, move):
        restore(R, x, nodes, keep_R, keep_x, keep_nodes)
        return False
    net_forces(state, work, system, stiffness, load, np.bool_(False), np.bool_(False), smooth)
    if residual(work.F, work.T, st) < before:
        return True
    restore(R, x, nodes, keep_R, keep_x, keep_nodes)
    return False


@njit(cache=True, error_model="numpy", inline="always")
def restore(R, x, nodes, keep_R, keep_x, keep_nodes):
    copy_into(R, keep_R)
    copy_into(x, keep_x)
    copy_into(nodes, keep_nodes)


State = namedtuple("State", ["R", "x", "v", "w", "nodes", "nv"])
"""A run's mutable state: rotations (n_bodies, 3, 3), centres of mass (n_bodies, 3) mm, velocities
(n_bodies, 3) mm/s and angular velocities (n_bodies, 3) rad/s of the bodies; RSC membrane node positions
(n_nodes, 3) mm and velocities (n_nodes, 3) mm/s."""
Work = namedtuple("Work", ["active", "n_active", "ref", "F", "T", "node_force", "stats", "bundle"])
"""A run's scratch: active contact samples, their count per pair and the pair transforms when they
were filled (n_pairs, 12; NaN to refill), forces (n_bodies, 3) N and torques (n_bodies, 3) N·mm on the
bodies, membrane node forces (n_nodes, 3) N, per-pair contact stats (n_pairs, 3), bundle forces (n_bundles,) N."""


@njit(cache=True)
def new_work(grids, nodes):
    """A zeroed `Work` for the contact grids and a membrane of nodes (n_nodes, 3)."""
    n_pairs = grids.pair_bones.shape[0]
    return Work(
        np.zeros(grids.points.shape[0], np.int64),
        np.zeros(n_pairs, np.int64),
        np.full((n_pairs, 12), np.nan),
        np.zeros((N_BONES, 3)),
        np.zeros((N_BONES, 3)),
        np.zeros_like(nodes),
        np.zeros((n_pairs, 3)),
        np.zeros(N_LIGAMENTS),
    )


Stiffness = namedtuple("Stiffness", ["f_l0", "f_K", "m_l0", "m_K", "node_mass"])
"""A design's zero-load lengths (mm) and stiffnesses of the fibres and the membrane connectors, and the
membrane's free-node mass (t) its connectors need (`arrays.node_mass`)."""
Load = namedtuple("Load", ["body", "point", "direction", "tension"])
"""The driver's loads as lines of action (the tendons where they enter, `drivers.Loads`): each line's
body (n_lines,) int64, point (n_lines, 3) mm fixed in the body (RCS at neutral), direction (n_lines, 3)
unit, RCS, and tension N: (n_lines,) at one state, (n_frames, n_lines) per frame in `Frames`."""
Target = namedtuple("Target", ["rotation", "centre", "load"])
"""Where a step, or a stage's end, puts the capitate and the driver's lines: its rotation (3, 3), its centre
of mass (3,) mm (held by the experimental driver only: the loaded driver's centre is free), and the lines
(`Load`) at that step's tensions (n_lines,) N."""
Carry = namedtuple("Carry", ["fire", "metric", "substeps"])
"""What `explicit_step` carries from one step to the next beside the `State`: FIRE's [alpha, steps with
positive power, 1 after a restart] (3,) (`integrator.fire_step`), the block mass (`preconditioner.Metric`)
and the membrane substeps' scratch (2, n_nodes, 3) (`membrane.new_scratch`)."""
