"""The explicit integrator's update rules (Numba): semi-implicit Euler moves of the free bodies, FIRE
relaxation and the kinetic energy.

Units: mm, s, t (tonnes), N; velocities mm/s, angular velocities rad/s. `move_diagonal` steps each
free body under its (scaled) mass and inertia with mass-proportional damping; `move_blocks` under the
preconditioner's block mass (`preconditioner`), FIRE (Bitzek et al. 2006) damping it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from wrist_env.model import CAPITATE, FREE
from wrist_env.solver.arrays import LOADED
from wrist_env.solver.preconditioner import SOLVED, dof
from wrist_env.solver.rigid import LEVER_MM, rotate_in_place

FIRE_F_ALPHA, FIRE_N_MIN = 0.99, 5


@njit(cache=True, error_model="numpy", inline="always")
def mix(vel, force, a):
    """FIRE mixing of one velocity group (rows of `vel`) towards its force direction."""
    vn = 0.0
    fn = 0.0
    for i in range(vel.shape[0]):
        for k in range(3):
            vn += vel[i, k] * vel[i, k]
            fn += force[i, k] * force[i, k]
    if fn > 0.0:
        c = a * np.sqrt(vn / fn)
        for i in range(vel.shape[0]):
            for k in range(3):
                vel[i, k] = (1.0 - a) * vel[i, k] + c * force[i, k]


@njit(cache=True, error_model="numpy", inline="always")
def force_of(F, T, b, i):
    """Generalized force of body b's unknown i (`preconditioner.dof`): F (N) then T (N·mm)."""
    return F[b, i] if i < 3 else T[b, i - 3]


@njit(cache=True, error_model="numpy")
def mix_metric(v, w, F, T, st, m, a):
    """FIRE mixing of each free body's velocity (v; w) towards M⁻¹(F; T) in the block mass's metric
    (preconditioned FIRE): u ← (1 − a)·u + a·|u|_M·M⁻¹g / |M⁻¹g|_M."""
    M, Minv = m.mass, m.inverse
    for b in SOLVED:
        i0, nb = dof(st, b)
        if i0 < 0:
            continue
        vn = 0.0
        fn = 0.0
        for i in range(nb):
            ui = v[b, i] if i < 3 else w[b, i - 3]
            gi = force_of(F, T, b, i)
            for j in range(nb):
                uj = v[b, j] if j < 3 else w[b, j - 3]
                vn += ui * M[i0 + i, i0 + j] * uj
                fn += gi * Minv[i0 + i, i0 + j] * force_of(F, T, b, j)
        if fn <= 0.0:
            continue
        c = a * np.sqrt(max(vn, 0.0) / fn)
        for i in range(nb):
            di = 0.0
            for j in range(nb):
                di += Minv[i0 + i, i0 + j] * force_of(F, T, b, j)
            if i < 3:
                v[b, i] = (1.0 - a) * v[b, i] + c * di
            else:
                w[b, i - 3] = (1.0 - a) * w[b, i - 3] + c * di


@njit(cache=True, error_model="numpy")
def fire_step(state, work, st, fire, m, preconditioned):
    """FIRE relaxation (Bitzek et al. 2006) at a fixed step: mix the velocities of `state` (`step.State`: the
    bodies' v, w and the membrane nodes' nv) towards the forces of `work` (`step.Work`: F, T, node_force)
    while the power is positive, stop everything when it turns negative.
    fire = [alpha, steps with positive power, 1 after a restart (the caller clears it)]; m the block mass
    (`preconditioner.Metric`); `preconditioned` (a compile-time constant, `kernel._run`): whether
    st.block_mass may be on."""
    v, w, nv = state.v, state.w, state.nv
    F, T, node_force = work.F, work.T, work.node_force
    power = 0.0
    for k in range(3):
        for b in FREE:
            power += F[b, k] * v[b, k] + T[b, k] * w[b, k]
        if st.driver == LOADED:
            power += F[CAPITATE, k] * v[CAPITATE, k]
        for i in range(nv.shape[0]):
            power += node_force[i, k] * nv[i, k]
    if power > 0.0:
        a = fire[0]
        if preconditioned and st.block_mass:
            mix_metric(v, w, F, T, st, m, a)
        else:
            for b in FREE:
                mix(v[b : b + 1], F[b : b + 1], a)
                mix(w[b : b + 1], T[b : b + 1], a)
            if st.driver == LOADED:
                mix(v[CAPITATE : CAPITATE + 1], F[CAPITATE : CAPITATE + 1], a)
        mix(nv, node_force, a)
        fire[1] += 1.0
        if fire[1] > FIRE_N_MIN:
            fire[0] *= FIRE_F_ALPHA
    else:
        v[:] = 0.0
        w[:] = 0.0
        nv[:] = 0.0
        fire[0] = st.fire_alpha0
        fire[1] = 0.0
        fire[2] = 1.0


@njit(cache=True, error_model="numpy")
def move_diagonal(state, work, bod, st):
    """Semi-implicit Euler of the free bodies of `state` (`step.State`) under the forces of `work`
    (`step.Work`) and their (scaled) mass and inertia (`arrays.Bodies`), with mass-proportional damping."""
    R, x, v, w = state.R, state.x, state.v, state.w
    F, T = work.F, work.T
    dt = st.dt
    lin = 1.0 / (1.0 + st.damping * dt)
    rot = 1.0 / (1.0 + st.rot_damping * dt)
    for b in FREE:
        for k in range(3):
            v[b, k] = (v[b, k] + dt * bod.inv_mass[b] * F[b, k]) * lin
            x[b, k] += dt * v[b, k]
        # angular acceleration R I⁻¹ Rᵀ T, world frame
        Rb, J = R[b], bod.inv_inertia[b]
        u0 = Rb[0, 0] * T[b, 0] + Rb[1, 0] * T[b, 1] + Rb[2, 0] * T[b, 2]
        u1 = Rb[0, 1] * T[b, 0] + Rb[1, 1] * T[b, 1] + Rb[2, 1] * T[b, 2]
        u2 = Rb[0, 2] * T[b, 0] + Rb[1, 2] * T[b, 1] + Rb[2, 2] * T[b, 2]
        a0 = J[0, 0] * u0 + J[0, 1] * u1 + J[0, 2] * u2
        a1 = J[1, 0] * u0 + J[1, 1] * u1 + J[1, 2] * u2
        a2 = J[2, 0] * u0 + J[2, 1] * u1 + J[2, 2] * u2
        for k in range(3):
            w[b, k] = (w[b, k] + dt * (Rb[k, 0] * a0 + Rb[k, 1] * a1 + Rb[k, 2] * a2)) * rot
        rotate_in_place(Rb, w[b, 0] * dt, w[b, 1] * dt, w[b, 2] * dt)
    if st.driver == LOADED:
        for k in range(3):
            v[CAPITATE, k] = (v[CAPITATE, k] + dt * bod.inv_mass[CAPITATE] * F[CAPITATE, k]) * lin
            x[CAPITATE, k] += dt * v[CAPITATE, k]


@njit(cache=True, error_model="numpy")
def move_blocks(state, work, st, m):
    """Semi-implicit Euler of the free bodies of `state` (`step.State`) under the forces g of `work`
    (`step.Work`) and the block mass m (`preconditioner.Metric`): u ← u + dt·M⁻¹g (FIRE damps it),
    the velocity cut where a body's step would move it more than st.block_max_move_mm (its shift
    plus its rotation × LEVER_MM): the mass is a linearization, and a contact that closes between
    refreshes is stiffer than it says."""
    R, x, v, w = state.R, state.x, state.v, state.w
    F, T = work.F, work.T
    dt = st.dt
    Minv = m.inverse
    for b in SOLVED:
        i0, nb = dof(st, b)
        if i0 < 0:
            continue
        for i in range(nb):
            acc = 0.0
            for j in range(nb):
                acc += Minv[i0 + i, i0 + j] * force_of(F, T, b, j)
            if i < 3:
                v[b, i] += dt * acc
            else:
                w[b, i - 3] += dt * acc
        move = dt * np.sqrt(v[b, 0] ** 2 + v[b, 1] ** 2 + v[b, 2] ** 2)
        if nb == 6:
            move += dt * LEVER_MM * np.sqrt(w[b, 0] ** 2 + w[b, 1] ** 2 + w[b, 2] ** 2)
        if move > st.block_max_move_mm:
            cut = st.block_max_move_mm / move
            for k in range(3):
                v[b, k] *= cut
                w[b, k] *= cut
        for k in range(3):
            x[b, k] += dt * v[b, k]
        if nb == 6:
            rotate_in_place(R[b], w[b, 0] * dt, w[b, 1] * dt, w[b, 2] * dt)


@njit(cache=True, error_model="numpy")
def kinetic_energy(state, bod, st, node_mass, m, preconditioned):
    """Kinetic energy (N·mm) of the free bodies (`arrays.Bodies` bod) and membrane nodes of mass `node_mass`
    (t) at `state` (`step.State`) (mass-scaled; with st.block_mass, in the block mass m; `preconditioned`
    as in `fire_step`)."""
    R, v, w, nv = state.R, state.v, state.w, state.nv
    ke = 0.0
    if preconditioned and st.block_mass:
        for b in SOLVED:
            i0, nb = dof(st, b)
            for i in range(nb if i0 >= 0 else 0):
                ui = v[b, i] if i < 3 else w[b, i - 3]
                for j in range(nb):
                    ke += 0.5 * ui * m.mass[i0 + i, i0 + j] * (v[b, j] if j < 3 else w[b, j - 3])
    else:
        for b in FREE:
            # body-frame angular velocity Rᵀw against the neutral-pose inertia
            u0 = R[b, 0, 0] * w[b, 0] + R[b, 1, 0] * w[b, 1] + R[b, 2, 0] * w[b, 2]
            u1 = R[b, 0, 1] * w[b, 0] + R[b, 1, 1] * w[b, 1] + R[b, 2, 1] * w[b, 2]
            u2 = R[b, 0, 2] * w[b, 0] + R[b, 1, 2] * w[b, 1] + R[b, 2, 2] * w[b, 2]
            I = bod.inertia[b]
            rot = (
                u0 * (I[0, 0] * u0 + I[0, 1] * u1 + I[0, 2] * u2)
                + u1 * (I[1, 0] * u0 + I[1, 1] * u1 + I[1, 2] * u2)
                + u2 * (I[2, 0] * u0 + I[2, 1] * u1 + I[2, 2] * u2)
            )
            ke += 0.5 * bod.mass[b] * (v[b, 0] ** 2 + v[b, 1] ** 2 + v[b, 2] ** 2) + 0.5 * rot
        if st.driver == LOADED:
            ke += 0.5 * bod.mass[CAPITATE] * (v[CAPITATE, 0] ** 2 + v[CAPITATE, 1] ** 2 + v[CAPITATE, 2] ** 2)
    for i in range(nv.shape[0]):
        ke += 0.5 * node_mass * (nv[i, 0] ** 2 + nv[i, 1] ** 2 + nv[i, 2] ** 2)
    return ke
