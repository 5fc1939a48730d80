"""The block mass of the free bones: the explicit solver's preconditioner (Numba).

A quasi-static answer does not depend on the masses; only the path to it and its
speed do. The explicit step is bounded by the stiffest mode and a hold lasts as
long as the softest mode needs, so the steps follow the spread √(λmax/λmin) of
M⁻¹K. With diagonal, isotropic masses that spread is large, because a carpal
bone's stiff and soft directions lie off its axes (contact normals, the coupling
of translation and rotation). Here each free bone gets one 6×6 mass block (the
loaded capitate's translations a 3×3 one) proportional to its own block of the
tangent stiffness K, so each bone's directions relax at about one rate; the
update stays explicit (a = M⁻¹F, one small inverse per bone).

The tangent K is `tangent`'s (the Gauss–Newton tangent of the force kernels).

Each block's eigenvalues, in the metric of the bone's physical (scaled) mass and
inertia, are floored at `block_floor` × the largest of any bone (a torn ligament
or an open contact leaves a direction with no stiffness), and the blocks are
scaled together so that the stiffest mode of the whole tangent, the couplings
between bones included, runs at dt·ω = `block_courant`.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from wrist_env.model import CAPITATE, FREE, N_BODIES
from wrist_env.solver.arrays import LOADED
from wrist_env.solver.rigid import copy_into

N_FREE_DOF = 6 * len(FREE)
N_DOF = N_FREE_DOF + 3
"""Unknowns of the tangent: 6 per free body (`model.FREE`, shift then rotation), then the loaded
capitate's shift (3)."""
FIRST_DOF = np.full(N_BODIES, -1, np.int64)
FIRST_DOF[list(FREE)] = 6 * np.arange(len(FREE))
"""Each body's first unknown (-1: none; the loaded capitate's is `N_FREE_DOF`)."""
SOLVED = FREE + (CAPITATE,)
"""The bodies with unknowns (`dof`), in their order."""
POWER_ITERATIONS = 30
"""Power iterations for the whole tangent's stiffest mode (a Rayleigh quotient: converged to < 1 %)."""

Metric = namedtuple("Metric", ["stiffness", "mass", "inverse", "block", "coupling", "lever", "product"])
"""The block mass: the free bones' tangent stiffness (N_DOF, N_DOF) (N/mm, N/rad, N·mm/rad); the mass
(t, t·mm, t·mm²) and its inverse (N_DOF, N_DOF), block diagonal; scratch: a 6×6 block, a 3×3 coupling (N/mm),
two levers [I; [r]×] (2, 6, 3) and a product (6, 3)."""


@njit(cache=True)
def metric():
    """A zeroed `Metric`."""
    return Metric(
        np.zeros((N_DOF, N_DOF)),
        np.zeros((N_DOF, N_DOF)),
        np.zeros((N_DOF, N_DOF)),
        np.zeros((6, 6)),
        np.zeros((3, 3)),
        np.zeros((2, 6, 3)),
        np.zeros((6, 3)),
    )


@njit(cache=True, error_model="numpy")
def dof(st, b):
    """(first unknown, number of unknowns) of body b; (-1, 0) if it is not free or b < 0 (a membrane's
    free node: `add_point`'s convention; a negative index would read the last body's entry)."""
    if b < 0:
        return -1, 0
    i0 = FIRST_DOF[b]
    if i0 >= 0:
        return i0, 6
    if b == CAPITATE and st.driver == LOADED:
        return N_FREE_DOF, 3
    return -1, 0


@njit(cache=True, error_model="numpy")
def _spd_inverse(A, i0, n, out):
    """out[i0:i0+n, i0:i0+n] ← the inverse of A's symmetric positive-definite block there (Cholesky);
    False if the block is not positive definite."""
    L = np.zeros((6, 6))
    for i in range(n):
        for j in range(i + 1):
            acc = A[i0 + i, i0 + j]
            for k in range(j):
                acc -= L[i, k] * L[j, k]
            if i == j:
                if not acc > 0.0:
                    return False
                L[i, i] = np.sqrt(acc)
            else:
                L[i, j] = acc / L[j, j]
    Linv = np.zeros((6, 6))
    for i in range(n):
        Linv[i, i] = 1.0 / L[i, i]
        for j in range(i):
            acc = 0.0
            for k in range(j, i):
                acc -= L[i, k] * Linv[k, j]
            Linv[i, j] = acc / L[i, i]
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for k in range(max(i, j), n):
                acc += Linv[k, i] * Linv[k, j]
            out[i0 + i, i0 + j] = acc
    return True


@njit(cache=True, error_model="numpy")
def _matvec(A, lo, hi, v, out):
    """out ← A[lo:hi, lo:hi] v."""
    for i in range(hi - lo):
        acc = 0.0
        for j in range(hi - lo):
            acc += A[lo + i, lo + j] * v[j]
        out[i] = acc


@njit(cache=True, error_model="numpy")
def _top(K, M, Minv, lo, hi):
    """Largest λ of K v = λ M v over the unknowns lo:hi (K symmetric positive semi-definite, M symmetric
    positive definite, Minv its inverse) by power iteration on Minv·K; the Rayleigh quotient vᵀKv / vᵀMv."""
    n = hi - lo
    v = np.ones(n)
    Kv = np.empty(n)
    Mv = np.empty(n)
    top = 0.0
    for _ in range(POWER_ITERATIONS):
        _matvec(K, lo, hi, v, Kv)
        _matvec(M, lo, hi, v, Mv)
        vMv = vKv = 0.0
        for i in range(n):
            vMv += v[i] * Mv[i]
            vKv += v[i] * Kv[i]
        if not vMv > 0.0:
            return 0.0
        top = vKv / vMv
        _matvec(Minv, lo, hi, Kv, v)
        norm = 0.0
        for i in range(n):
            norm += v[i] * v[i]
        norm = np.sqrt(norm)
        if norm == 0.0:
            return 0.0
        for i in range(n):
            v[i] /= norm
    return top


@njit(cache=True, error_model="numpy")
def block_mass(R, bod, st, m):
    """Fill m.mass and m.inverse from m.stiffness (`tangent`): each free bone's block plus st.block_floor ×
    λ_top × its physical mass (λ_top: the largest K v = λ M0 v of any bone's block, M0 its physical scaled
    mass and inertia), all blocks scaled so that the whole tangent's stiffest mode runs at dt·ω =
    st.block_courant. Without stiffness (nothing in contact, every fibre slack) the physical mass; a
    state gone non-finite keeps the last mass."""
    if not (np.all(np.isfinite(m.stiffness)) and np.all(np.isfinite(R))):
        return
    K = m.stiffness
    M0 = np.zeros((N_DOF, N_DOF))
    M0inv = np.zeros((N_DOF, N_DOF))
    n = 0
    for b in SOLVED:
        i0, nb = dof(st, b)
        if i0 < 0:
            continue
        n = i0 + nb
        for k in range(3):
            M0[i0 + k, i0 + k] = bod.mass[b]
            M0inv[i0 + k, i0 + k] = bod.inv_mass[b]
        if nb == 6:
            for p in range(3):
                for q in range(3):
                    acc = 0.0
                    inv = 0.0
                    for r in range(3):
                        for t in range(3):
                            acc += R[b, p, r] * bod.inertia[b, r, t] * R[b, q, t]
                            inv += R[b, p, r] * bod.inv_inertia[b, r, t] * R[b, q, t]
                    M0[i0 + 3 + p, i0 + 3 + q] = acc
                    M0inv[i0 + 3 + p, i0 + 3 + q] = inv
    top = 0.0
    for b in SOLVED:
        i0, nb = dof(st, b)
        if i0 >= 0:
            top = max(top, _top(K, M0, M0inv, i0, i0 + nb))
    D = m.mass
    Dinv = m.inverse
    D[:] = 0.0
    Dinv[:] = 0.0
    ok = top > 0.0
    for b in SOLVED:
        i0, nb = dof(st, b)
        if i0 < 0:
            continue
        for i in range(nb):
            for j in range(nb):
                D[i0 + i, i0 + j] = (
                    (0.5 * (K[i0 + i, i0 + j] + K[i0 + j, i0 + i]) + st.block_floor * top * M0[i0 + i, i0 + j])
                    if ok
                    else M0[i0 + i, i0 + j]
                )
        if not _spd_inverse(D, i0, nb, Dinv):
            ok = False
    if not ok:  # no stiffness (or a block not positive definite): the physical mass
        copy_into(D, M0)
        copy_into(Dinv, M0inv)
        return
    scale = _top(K, D, Dinv, 0, n) * (st.dt / st.block_courant) ** 2
    if not scale > 0.0:
        scale = 1.0
    D *= scale
    Dinv /= scale
