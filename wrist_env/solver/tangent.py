"""The free bones' tangent stiffness (Numba), which the block mass (`preconditioner`) and the Newton
reference (`equilibrium`) take.

K is the Gauss–Newton tangent of the force kernels: each overclosed contact
sample κ·JJᵀ with J = [n; r×n] and κ = p′(ε)·A/h; each taut fibre, and each RSC
connector at its attached ends, dT/dl·uuᵀ + T/L·(I − uuᵀ) between its ends; the
membrane's free nodes' contact with the scaphoid k·nnᵀ; the planar joints'
in-plane springs (`forces.joint_forces`: capitohamate, lunotriquetral) Σ kₖeₖeₖᵀ between their
centre points and Σ k₃₊ₖeₖeₖᵀ on their bodies' rotations. No geometric terms of
the moments. Coordinates per bone: shift (mm, world) then rotation (rad, world),
as `equilibrium.tangent_stiffness`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

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
def _add_block(K, i0, ni, Ga, k, j0, nj, Gb, H, sign):
    """K[i0:i0+ni, j0:j0+nj] += sign · Ga k Gbᵀ (levers (6, 3), k (3, 3)); H (6, 3) scratch."""
    for i in range(ni):
        for q in range(3):
            H[i, q] = Ga[i, 0] * k[0, q] + Ga[i, 1] * k[1, q] + Ga[i, 2] * k[2, q]
    for i in range(ni):
        for j in range(nj):
            K[i0 + i, j0 + j] += sign * (H[i, 0] * Gb[j, 0] + H[i, 1] * Gb[j, 1] + H[i, 2] * Gb[j, 2])


@njit(cache=True, error_model="numpy")
def add_point(K, st, a, ra, b, rb, m):
    """A point coupling m.coupling (3×3, N/mm) between body a at lever ra and body b at lever rb (mm,
    world, from each centre of mass): GₐᵀkGₐ and G_bᵀkG_b on the diagonal, −GₐᵀkG_b and its transpose
    off it (G = [I, −[r]×]: a body's move at the point)."""
    ia, na = dof(st, a)
    ib, nb = dof(st, b)
    G, H, k = m.lever, m.product, m.coupling
    _lever(G[0], ra)
    _lever(G[1], rb)
    if ia >= 0:
        _add_block(K, ia, na, G[0], k, ia, na, G[0], H, 1.0)
    if ib >= 0:
        _add_block(K, ib, nb, G[1], k, ib, nb, G[1], H, 1.0)
    if ia >= 0 and ib >= 0:
        _add_block(K, ia, na, G[0], k, ib, nb, G[1], H, -1.0)
        _add_block(K, ib, nb, G[1], k, ia, na, G[0], H, -1.0)


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
def _pair_sums(grids, b, M, samples, law, com0, S, J, smooth):
    """S (6×6) ← Σ κ J Jᵀ over a pair's overclosed samples, J = [n; c×n] in the grid bone b's neutral
    frame about its centre (κ = p′(ε)·A/h, N/mm); J (6,) scratch."""
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
def tangent(R, x, nodes, system, stiffness, active, n_active, m, smooth):
    """Assemble m.stiffness, the Gauss–Newton tangent of `system` (`arrays.System`) under a design's
    `stiffness` at the state (R, x, nodes) over the active contact samples (as the last force evaluation
    left them)."""
    _, grids, law, fib, mem, st = system
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
        _pair_sums(grids, b, M, active[start : start + n_active[p]], law, com0, S, J, smooth)
        for u in range(6):
            for v in range(u):
                S[u, v] = S[v, u]
        _add_pair(K, st, a, b, R, x, S)
    ra = np.zeros(3)
    rb = np.zeros(3)
    o, ins = fib.origin, fib.insertion
    for i in range(stiffness.f_l0.shape[0]):
        if stiffness.f_K[i] == 0.0:
            continue
        a, b = fib.bones[i, 0], fib.bones[i, 1]
        pa = to_world(R, x, com0, a, o[i, 0], o[i, 1], o[i, 2])
        pb = to_world(R, x, com0, b, ins[i, 0], ins[i, 1], ins[i, 2])
        _element(K, st, m, a, pa, b, pb, x, stiffness.f_K[i], stiffness.f_l0[i], ra, rb)
    for c in range(stiffness.m_l0.shape[0]):
        i, j = mem.connectors[c, 0], mem.connectors[c, 1]
        a, b = mem.bone[i], mem.bone[j]
        if stiffness.m_K[c] == 0.0:
            continue
        pa = (nodes[i, 0], nodes[i, 1], nodes[i, 2])
        pb = (nodes[j, 0], nodes[j, 1], nodes[j, 2])
        _element(K, st, m, a, pa, b, pb, x, stiffness.m_K[c], stiffness.m_l0[c], ra, rb)
    _membrane_contact(K, st, m, R, x, com0, mem, nodes, ra, rb)
    _joint(K, st, m, R, x, com0, system.bodies, ra, rb)


@njit(cache=True, error_model="numpy")
def _joint(K, st, m, R, x, com0, bod, ra, rb):
    """The planar joints' springs (`forces.joint_forces`): each joint's shift stiffness between its moving
    body's and its carrier's centre points, its turn stiffness Σ k₃₊ₖeₖeₖᵀ on the two bodies' rotations
    (on their diagonal blocks, minus it between them; a carrier without rotational unknowns, the driven
    capitate, adds none)."""
    k_shift = m.coupling
    for j in range(bod.joint_stiffness.shape[0]):
        k = bod.joint_stiffness[j]
        if k[0] == 0.0 and k[1] == 0.0 and k[2] == 0.0 and k[3] == 0.0 and k[4] == 0.0 and k[5] == 0.0:
            continue
        a, b = bod.joint_bodies[j, 0], bod.joint_bodies[j, 1]
        c, E = bod.joint_centre[j], bod.joint_axes[j]
        k_shift[:] = 0.0
        ia, na = dof(st, a)
        ib, nb = dof(st, b)
        for q in range(3):
            e = rotate(R, b, E[q, 0], E[q, 1], E[q, 2])
            for p in range(3):
                for r in range(3):
                    k_shift[p, r] += k[q] * e[p] * e[r]
                    turn = k[3 + q] * e[p] * e[r]
                    if na == 6:
                        K[ia + 3 + p, ia + 3 + r] += turn
                    if nb == 6:
                        K[ib + 3 + p, ib + 3 + r] += turn
                    if na == 6 and nb == 6:
                        K[ia + 3 + p, ib + 3 + r] -= turn
                        K[ib + 3 + p, ia + 3 + r] -= turn
        pa = to_world(R, x, com0, a, c[0], c[1], c[2])
        pb = to_world(R, x, com0, b, c[0], c[1], c[2])
        for e in range(3):
            ra[e] = pa[e] - x[a, e]
            rb[e] = pb[e] - x[b, e]
        add_point(K, st, a, ra, b, rb, m)


@njit(cache=True, error_model="numpy")
def _element(K, st, m, a, pa, b, pb, x, scale, l0, ra, rb):
    """A Blankevoort element of scale `scale` (N) and zero-load length l0 (mm) between world points pa on
    body a and pb on body b (a body < 0: a membrane's free node, not an unknown); nothing if slack."""
    if dof(st, a)[0] < 0 and dof(st, b)[0] < 0:
        return
    dx, dy, dz = pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]
    length = np.sqrt(dx * dx + dy * dy + dz * dz)
    strain = length / l0 - 1.0
    if strain <= 0.0:
        return
    along = blankevoort_slope(scale, strain) / l0
    _axial(m.coupling, dx / length, dy / length, dz / length, along, blankevoort_force(scale, strain) / length)
    for e in range(3):
        ra[e] = pa[e] - x[a, e] if a >= 0 else 0.0
        rb[e] = pb[e] - x[b, e] if b >= 0 else 0.0
    add_point(K, st, max(a, -1), ra, max(b, -1), rb, m)


@njit(cache=True, error_model="numpy")
def _membrane_contact(K, st, m, R, x, com0, mem, nodes, r, node_lever):
    """The membrane's free nodes pressing on the scaphoid: membrane_contact_stiffness (N/mm) along the normal."""
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
        for e in range(3):
            r[e] = nodes[i, e] - x[s, e]
        add_point(K, st, s, r, -1, node_lever, m)  # the node is no unknown: its lever is unused
