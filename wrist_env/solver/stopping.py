"""When a hold ends and when a run has failed (Numba): quasi-static equilibrium of the free bodies
(net force N, net moment N·mm), the largest residual, and how far (mm) a free body has moved from its place.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from wrist_env.model import CAPITATE, HAMATE, TRAPEZIUM
from wrist_env.solver.arrays import EXPERIMENTAL
from wrist_env.solver.preconditioner import SOLVED
from wrist_env.solver.rigid import LEVER_MM


@njit(cache=True, error_model="numpy")
def displacement(R, x, com0, b):
    """How far (mm) free body b has moved from its place: the proximal row's (scaphoid, lunate, triquetrum)
    from its neutral place on the radius; the radial column's and the hamate's (`model.CARRIED`) from where the
    capitate carries them (the distal row moves as one, Akhbari 2019; at ±40° the capitate carries the
    column's centre 15–18 mm)."""
    d2 = 0.0
    for i in range(3):
        if b == TRAPEZIUM or b == HAMATE:
            carried = 0.0
            for j in range(3):
                carried += R[CAPITATE, i, j] * (com0[b, j] - com0[CAPITATE, j])
            d = x[b, i] - x[CAPITATE, i] - carried
        else:
            d = x[b, i] - com0[b, i]
        d2 += d * d
    return np.sqrt(d2)


@njit(cache=True, error_model="numpy")
def converged(F, T, bundle, st):
    """Quasi-static equilibrium: the net force (N) on every free body at most
    max(force_floor, tolerance × largest bundle force), the net moment (N·mm)
    at most that times LEVER_MM."""
    largest = 0.0
    for i in range(bundle.shape[0]):
        largest = max(largest, bundle[i])
    tol = max(st.force_floor, st.tolerance * largest)
    for b in SOLVED:
        if b == CAPITATE and st.driver == EXPERIMENTAL:
            continue
        f2 = F[b, 0] * F[b, 0] + F[b, 1] * F[b, 1] + F[b, 2] * F[b, 2]
        if not f2 <= tol * tol:
            return False
        if b != CAPITATE:
            t2 = T[b, 0] * T[b, 0] + T[b, 1] * T[b, 1] + T[b, 2] * T[b, 2]
            if not t2 <= (tol * LEVER_MM) ** 2:
                return False
    return True


@njit(cache=True, error_model="numpy")
def residual(F, T, st):
    """The largest net force (N) on a free body, or net moment (N·mm) / LEVER_MM."""
    worst = 0.0
    for b in SOLVED:
        if b == CAPITATE and st.driver == EXPERIMENTAL:
            continue
        worst = max(worst, np.sqrt(F[b, 0] ** 2 + F[b, 1] ** 2 + F[b, 2] ** 2))
        if b != CAPITATE:
            worst = max(worst, np.sqrt(T[b, 0] ** 2 + T[b, 1] ** 2 + T[b, 2] ** 2) / LEVER_MM)
    return worst
