"""Ligament kernels: tension-only Blankevoort fibres (Numba).

Strain ε = l / l0 − 1 with the spring parameter ε_l = 0.03: force
K·ε²/(4ε_l) for 0 ≤ ε ≤ 2ε_l, K·(ε − ε_l) above, zero below (N), where
K = k·l0 (N per unit strain) turns a stiffness k (N/mm) into the law's scale.
"""

from __future__ import annotations

from numba import njit

EPSILON_L = 0.03


@njit(cache=True, error_model="numpy")
def blankevoort_force(K, strain):
    """Tension (N) of a fibre of scale K (N per unit strain) at `strain`."""
    if strain <= 0.0:
        return 0.0
    if strain <= 2.0 * EPSILON_L:
        return K * strain * strain / (4.0 * EPSILON_L)
    return K * (strain - EPSILON_L)


@njit(cache=True, error_model="numpy")
def blankevoort_slope(K, strain):
    """dT/dε (N per unit strain) of a fibre of scale K at `strain` (0 when slack)."""
    if strain <= 0.0:
        return 0.0
    if strain <= 2.0 * EPSILON_L:
        return K * strain / (2.0 * EPSILON_L)
    return K


@njit(cache=True, error_model="numpy")
def blankevoort_energy(K, l0, strain):
    """Strain energy (N·mm) of a fibre of scale K, zero-load length l0 (mm), at `strain`."""
    if strain <= 0.0:
        return 0.0
    el = EPSILON_L
    if strain <= 2.0 * el:
        return K * l0 * strain**3 / (12.0 * el)
    return K * l0 * (2.0 * el * el / 3.0 + 0.5 * strain * strain - el * strain)
