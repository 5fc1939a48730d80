"""The free bones' tangent stiffness (Numba), which the block mass (`preconditioner`) and the Newton
reference (`equilibrium`) take.

K is the Gauss–Newton tangent of the force kernels: each overclosed contact
sample κ·JJᵀ with J = [n; r×n] and κ = p′(ε)·A/h; each taut fibre, and each RSC
connector at its attached ends, dT/dl·uuᵀ + T/L·(I − uuᵀ) between its ends; the
membrane's free nodes' contact with the scaphoid k·nnᵀ; the capitohamate joint's
in-plane spring (`forces.joint_forces`) Σ kₖeₖeₖᵀ between its centre points and
Σ k₃₊ₖeₖeₖᵀ on the hamate's rotations. No geometric terms of
the moments. Coordinates per bone: shift (mm, world) then rotation (rad, world),
as `equilibrium.tangent_stiffness`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from wrist_env.model import CAPITATE, HAMATE
from wrist_env.solver.contact import law_slope, sdf_lookup_scalar
from wrist_env.solver.forces import pair_transform, rotate, sample_lookup, sample_lookup_smooth, to_local, to_world
from wrist_env.solver.ligaments import blankevoort_force, blankevoort_slope
from wrist_env.solver.preconditioner import dof


@njit(cache=True, error_model="numpy")
def _cross(r, p, q):
    """[r]× entry (p, q)."""
    if p == q:
        return 0.0
    if p == 0:
        return -r[2] if q == 1 else r[1]
    if p == 1:
        return r[2] if q == 0 else -r[0]
    return -r[1] if q == 0 else r[0]


@njit(cache=True, error_model="numpy")
def _lever(G, r):
    """G (6, 3) ← [I; [r]×]: a force at lever r (mm) as the force and moment on a body."""
    G[:] = 0.0
    G[0, 0] = G[1, 1] = G[2, 2] = 1.0
    G[3, 1], G[3, 2] = -r[2], r[1]
    G[4, 0], G[4, 2] = r[2], -r[0]
    G[5, 0], G[5, 1] = -r[1], r[0]


@njit(cache=True, error_model="numpy")
def _add_block(K, rows, Ga, cols, Gb, m, sign):
    """K[i0:i0+ni, j0:j0+nj] += sign · Ga k Gbᵀ, rows = (i0, ni) and cols = (j0, nj) as `dof` gives them
    (levers Ga, Gb (6, 3); k = m.coupling (3, 3); m.product (6, 3) scratch)."""
    i0, ni = rows
    j0, nj = cols
    k, H = m.coupling, m.product
    for i in range(ni):
        for q in range(3):
            H[i, q] = Ga[i, 0] * k[0, q] + Ga[i, 1] * k[1, q] + Ga[i, 2] * k[2, q]
    for i in range(ni):
        for j in range(nj):
            K[i0 + i, j0 + j] += sign * (H[i, 0] * Gb[j, 0] + H[i, 1] * Gb[j, 1] + H[i, 2] * Gb[j, 2])


@njit(cache=True, error_model="numpy")
def add_point(K, st, a, ra, b, rb, m):
    """A point coupling m.coupling (3×3, N/mm) between body a at lever ra and body b at lever rb (mm,
    world, from each centre of mass; 3-tuples): GₐᵀkGₐ and G_bᵀkG_b on the diagonal, −GₐᵀkG_b and its
    transpose off it (G = [I, −[r]×]: a body's move at the point)."""
    A = dof(st, a)
    B = dof(st, b)
    G = m.lever
    _lever(G[0], ra)
    _lever(G[1], rb)
    if A[0] >= 0:
        _add_block(K, A, G[0], A, G[0], m, 1.0)
    if B[0] >= 0:
        _add_block(K, B, G[1], B, G[1], m, 1.0)
    if A[0] >= 0 and B[0] >= 0:
        _add_block(K, A, G[0], B, G[1], m, -1.0)
        _add_block(K, B, G[1], A, G[0], m, -1.0)


@njit(cache=True, error_model="numpy")
def _axial(k, ux, uy, uz, along, across):
    """k ← along·uuᵀ + across·(I − uuᵀ) (N/mm)."""
    u = (ux, uy, uz)
    for p in range(3):
        for q in range(3):
            k[p, q] = (along - across) * u[p] * u[q] + (across if p == q else 0.0)


@njit(cache=True, error_model="numpy")
def _product6(A, B, transposed):
    """A B (6×6), or A Bᵀ if `transposed` (explicit loops: a BLAS call costs more than the work)."""
    out = np.zeros((6, 6))
    for i in range(6):
        for j in range(6):
            acc = 0.0
            for q in range(6):
                acc += A[i, q] * (B[j, q] if transposed else B[q, j])
            out[i, j] = acc
    return out


@njit(cache=True, error_model="numpy")
def _add_pair(K, st, a, b, R, x, S):
    """A contact pair's summed κJJᵀ S (6×6, body b's neutral frame about its centre) into K: rotated to
    world for b, shifted by d = x_b − x_a for a (J_a = [n; (r_b + d)×n]), −J_aJ_bᵀ between them."""
    ia, na = dof(st, a)
    ib, nb = dof(st, b)
    W = np.zeros((6, 6))  # T S Tᵀ, T = blockdiag(R_b, R_b)
    for i in range(6):
        for j in range(6):
            acc = 0.0
            for p in range(3):
                rip = R[b, i % 3, p]
                for q in range(3):
                    acc += rip * S[3 * (i // 3) + p, 3 * (j // 3) + q] * R[b, j % 3, q]
            W[i, j] = acc
    d = (x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2])
    L = np.eye(6)  # J_a = L J_b
    for p in range(3):
        for q in range(3):
            L[3 + p, q] = _cross(d, p, q)
    LW = _product6(L, W, False)
    LWL = _product6(LW, L, True)
    if ib >= 0:
        for i in range(nb):
            for j in range(nb):
                K[ib + i, ib + j] += W[i, j]
    if ia >= 0:
        for i in range(na):
            for j in range(na):
                K[ia + i, ia + j] += LWL[i, j]
    if ia >= 0 and ib >= 0:
        for i in range(na):
            for j in range(nb):
                K[ia + i, ib + j] -= LW[i, j]
                K[ib + j, ia + i] -= LW[i, j]


@njit(cache=True, error_model="numpy")
def _pair_sums(system, b, M, samples, S, J, smooth):
    """S (6×6) ← Σ κ J Jᵀ over a pair's overclosed samples of `system` (`arrays.System`: its grids and
    contact law), J = [n; c×n] in the grid bone b's neutral frame about its centre (κ = p′(ε)·A/h,
    N/mm); J (6,) scratch."""
    grids, law, com0 = system.grids, system.law, system.bodies.com0
    S[:] = 0.0
    for s in samples:
        if smooth:
            d, gx, gy, gz, qx, qy, qz = sample_lookup_smooth(grids, b, M, s)
        else:
            d, gx, gy, gz, qx, qy, qz = sample_lookup(grids, b, M, s)
        gn = np.sqrt(gx * gx + gy * gy + gz * gz)
        if d >= 0.0 or gn < 1e-12:
            continue
        h = grids.thickness[s]
        kappa = law_slope(law, -d / h) * grids.area[s] / h
        nx, ny, nz = gx / gn, gy / gn, gz / gn
        cx, cy, cz = qx - com0[b, 0], qy - com0[b, 1], qz - com0[b, 2]
        J[0], J[1], J[2] = nx, ny, nz
        J[3], J[4], J[5] = cy * nz - cz * ny, cz * nx - cx * nz, cx * ny - cy * nx
        for u in range(6):
            ku = kappa * J[u]
            for v in range(u, 6):
                S[u, v] += ku * J[v]


@njit(cache=True, error_model="numpy")
def tangent(state, system, stiffness, work, m, smooth):
    """Assemble m.stiffness, the Gauss–Newton tangent of `system` (`arrays.System`) under a design's
    `stiffness` (`step.Stiffness`) at `state` (`step.State`: R, x, nodes) over the active contact samples
    of `work` (`step.Work`: active, n_active, as the last force evaluation left them)."""
    R, x, nodes = state.R, state.x, state.nodes
    grids, fib, mem, st = system.grids, system.fibres, system.membrane, system.settings
    com0 = system.bodies.com0
    K, S = m.stiffness, m.block
    K[:] = 0.0
    J = np.empty(6)
    for p in range(grids.pair_bones.shape[0]):
        a, b = grids.pair_bones[p, 0], grids.pair_bones[p, 1]
        if dof(st, a)[0] < 0 and dof(st, b)[0] < 0:
            continue
        M = pair_transform(R, x, com0, a, b)
        start = grids.sample_offsets[p]
        _pair_sums(system, b, M, work.active[start : start + work.n_active[p]], S, J, smooth)
        for u in range(6):
            for v in range(u):
                S[u, v] = S[v, u]
        _add_pair(K, st, a, b, R, x, S)
    o, ins = fib.origin, fib.insertion
    for i in range(stiffness.f_l0.shape[0]):
        if stiffness.f_K[i] == 0.0:
            continue
        a, b = fib.bones[i, 0], fib.bones[i, 1]
        pa = to_world(R, x, com0, a, o[i, 0], o[i, 1], o[i, 2])
        pb = to_world(R, x, com0, b, ins[i, 0], ins[i, 1], ins[i, 2])
        _element(K, st, m, x, (a, pa), (b, pb), stiffness.f_K[i], stiffness.f_l0[i])
    for c in range(stiffness.m_l0.shape[0]):
        i, j = mem.connectors[c, 0], mem.connectors[c, 1]
        a, b = mem.bone[i], mem.bone[j]
        if stiffness.m_K[c] == 0.0:
            continue
        pa = (nodes[i, 0], nodes[i, 1], nodes[i, 2])
        pb = (nodes[j, 0], nodes[j, 1], nodes[j, 2])
        _element(K, st, m, x, (a, pa), (b, pb), stiffness.m_K[c], stiffness.m_l0[c])
    _membrane_contact(K, m, state, system)
    _joint(K, m, state, system)


@njit(cache=True, error_model="numpy")
def _joint(K, m, state, system):
    """The capitohamate joint's spring (`forces.joint_forces`) at `state`: its shift stiffness between the
    hamate's and the capitate's centre points, its turn stiffness on the hamate's rotations (the capitate's
    rotations are prescribed: no unknowns)."""
    R, x = state.R, state.x
    bod, st = system.bodies, system.settings
    com0 = bod.com0
    k = bod.joint_stiffness
    c, E = bod.joint_centre, bod.joint_axes
    k_shift = m.coupling
    k_shift[:] = 0.0
    i0, n = dof(st, HAMATE)
    for a in range(3):
        e = rotate(R, CAPITATE, E[a, 0], E[a, 1], E[a, 2])
        for p in range(3):
            for q in range(3):
                k_shift[p, q] += k[a] * e[p] * e[q]
                if i0 >= 0:
                    K[i0 + 3 + p, i0 + 3 + q] += k[3 + a] * e[p] * e[q]
    ph = to_world(R, x, com0, HAMATE, c[0], c[1], c[2])
    pc = to_world(R, x, com0, CAPITATE, c[0], c[1], c[2])
    ra = (ph[0] - x[HAMATE, 0], ph[1] - x[HAMATE, 1], ph[2] - x[HAMATE, 2])
    rb = (pc[0] - x[CAPITATE, 0], pc[1] - x[CAPITATE, 1], pc[2] - x[CAPITATE, 2])
    add_point(K, st, HAMATE, ra, CAPITATE, rb, m)


@njit(cache=True, error_model="numpy")
def _element(K, st, m, x, end_a, end_b, scale, l0):
    """A Blankevoort element of scale `scale` (N) and zero-load length l0 (mm) between its ends (a, pa) and
    (b, pb): world points pa (mm) on body a and pb on body b (a body < 0: a membrane's free node, not an
    unknown), bodies' centres of mass x (n_bodies, 3) mm; nothing if slack."""
    a, pa = end_a
    b, pb = end_b
    if dof(st, a)[0] < 0 and dof(st, b)[0] < 0:
        return
    dx, dy, dz = pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]
    length = np.sqrt(dx * dx + dy * dy + dz * dz)
    strain = length / l0 - 1.0
    if strain <= 0.0:
        return
    along = blankevoort_slope(scale, strain) / l0
    _axial(m.coupling, dx / length, dy / length, dz / length, along, blankevoort_force(scale, strain) / length)
    ra = (pa[0] - x[a, 0], pa[1] - x[a, 1], pa[2] - x[a, 2]) if a >= 0 else (0.0, 0.0, 0.0)
    rb = (pb[0] - x[b, 0], pb[1] - x[b, 1], pb[2] - x[b, 2]) if b >= 0 else (0.0, 0.0, 0.0)
    add_point(K, st, max(a, -1), ra, max(b, -1), rb, m)


@njit(cache=True, error_model="numpy")
def _membrane_contact(K, m, state, system):
    """The membrane's free nodes of `state` pressing on the scaphoid: membrane_contact_stiffness (N/mm) along
    the normal."""
    R, x, nodes = state.R, state.x, state.nodes
    com0, mem, st = system.bodies.com0, system.membrane, system.settings
    s = mem.scaphoid
    for i in range(nodes.shape[0]):
        if mem.bone[i] >= 0:
            continue
        qx, qy, qz = to_local(R, x, com0, s, nodes[i, 0], nodes[i, 1], nodes[i, 2])
        d, gx, gy, gz = sdf_lookup_scalar(
            mem.grid_values, mem.grid_offset, mem.grid_shape, mem.grid_origin, mem.grid_spacing, qx, qy, qz
        )
        gn = np.sqrt(gx * gx + gy * gy + gz * gz)
        if d >= 0.0 or gn < 1e-12:
            continue
        nx = (R[s, 0, 0] * gx + R[s, 0, 1] * gy + R[s, 0, 2] * gz) / gn
        ny = (R[s, 1, 0] * gx + R[s, 1, 1] * gy + R[s, 1, 2] * gz) / gn
        nz = (R[s, 2, 0] * gx + R[s, 2, 1] * gy + R[s, 2, 2] * gz) / gn
        _axial(m.coupling, nx, ny, nz, st.membrane_contact_stiffness, 0.0)
        r = (nodes[i, 0] - x[s, 0], nodes[i, 1] - x[s, 1], nodes[i, 2] - x[s, 2])
        add_point(K, st, s, r, -1, (0.0, 0.0, 0.0), m)  # the node is no unknown: its lever is unused
