"""Cartilage contact kernels: signed-distance look-up and the tri-linear law (Numba).

A contact sample of one bone (its cartilage surface, bone frame) is looked up
in the signed-distance grid of the other bone (cartilage folded in). A
negative distance is an overclosure δ (mm); with the local total cartilage
thickness h (mm), strain e = δ / h gives the pressure p(e) (MPa) of the
tri-linear law; the force p·area (N) acts along the grid's gradient.
"""

from __future__ import annotations

import numpy as np
from numba import njit

OUTSIDE_MM = 1e3  # distance reported outside a grid: no contact


@njit(cache=True, error_model="numpy")
def sdf_lookup(values, offset, shape, origin, spacing, q):
    """Trilinear signed distance (mm) and its gradient (3,) at local point q (3,)."""
    d, gx, gy, gz = sdf_lookup_scalar(values, offset, shape, origin, spacing, q[0], q[1], q[2])
    return d, np.array([gx, gy, gz])


@njit(cache=True, error_model="numpy", inline="always")
def _cell(offset, shape, origin, spacing, qx, qy, qz):
    """(inside, first corner's index, x and y strides, fractions tx, ty, tz, 1/spacing) of the grid
    cell holding local point q; inside is False outside the grid."""
    nx, ny, nz = shape[0], shape[1], shape[2]
    inv = 1.0 / spacing
    fx = (qx - origin[0]) * inv
    fy = (qy - origin[1]) * inv
    fz = (qz - origin[2]) * inv
    if fx < 0.0 or fy < 0.0 or fz < 0.0 or fx >= nx - 1 or fy >= ny - 1 or fz >= nz - 1:
        return False, 0, 0, 0, 0.0, 0.0, 0.0, inv
    i = int(fx)
    j = int(fy)
    k = int(fz)
    return True, offset + (i * ny + j) * nz + k, ny * nz, nz, fx - i, fy - j, fz - k, inv


@njit(cache=True, error_model="numpy", inline="always")
def sdf_distance(values, offset, shape, origin, spacing, qx, qy, qz):
    """Trilinear signed distance (mm) at local point (qx, qy, qz); `OUTSIDE_MM` outside the grid."""
    inside, base, sx, sy, tx, ty, tz, _ = _cell(offset, shape, origin, spacing, qx, qy, qz)
    if not inside:
        return OUTSIDE_MM
    return _trilinear(values, base, sx, sy, tx, ty, tz)


@njit(cache=True, error_model="numpy", inline="always")
def _trilinear(values, base, sx, sy, tx, ty, tz):
    """Trilinear interpolation of the cell whose first corner is values[base] (strides sx, sy, 1)."""
    c00 = values[base] + (values[base + 1] - values[base]) * tz
    c01 = values[base + sy] + (values[base + sy + 1] - values[base + sy]) * tz
    c10 = values[base + sx] + (values[base + sx + 1] - values[base + sx]) * tz
    c11 = values[base + sx + sy] + (values[base + sx + sy + 1] - values[base + sx + sy]) * tz
    c0 = c00 + (c01 - c00) * ty
    c1 = c10 + (c11 - c10) * ty
    return c0 + (c1 - c0) * tx


@njit(cache=True, error_model="numpy", inline="always")
def sdf_lookup_scalar(values, offset, shape, origin, spacing, qx, qy, qz):
    """Trilinear signed distance (mm) and gradient components at local point (qx, qy, qz).

    values: C-order grids (float32, mm) flattened; offset: the grid's first value.
    """
    inside, base, sx, sy, tx, ty, tz, inv = _cell(offset, shape, origin, spacing, qx, qy, qz)
    if not inside:
        return OUTSIDE_MM, 0.0, 0.0, 0.0
    c000 = values[base]
    c001 = values[base + 1]
    c010 = values[base + sy]
    c011 = values[base + sy + 1]
    c100 = values[base + sx]
    c101 = values[base + sx + 1]
    c110 = values[base + sx + sy]
    c111 = values[base + sx + sy + 1]
    c00 = c000 + (c001 - c000) * tz
    c01 = c010 + (c011 - c010) * tz
    c10 = c100 + (c101 - c100) * tz
    c11 = c110 + (c111 - c110) * tz
    c0 = c00 + (c01 - c00) * ty
    c1 = c10 + (c11 - c10) * ty
    d = c0 + (c1 - c0) * tx
    gx = (c1 - c0) * inv
    gy = ((1 - tx) * (c01 - c00) + tx * (c11 - c10)) * inv
    dz0 = (1 - ty) * (c001 - c000) + ty * (c011 - c010)
    dz1 = (1 - ty) * (c101 - c100) + ty * (c111 - c110)
    gz = ((1 - tx) * dz0 + tx * dz1) * inv
    return d, gx, gy, gz


@njit(cache=True, error_model="numpy", inline="always")
def sdf_lookup_smooth(values, normals, offset, shape, origin, spacing, qx, qy, qz):
    """Trilinear signed distance (mm) at local point q and, where it is negative (overclosure),
    the direction interpolated trilinearly from `nodal_normals` (continuous across cells, unlike
    the derivative of the trilinear distance, which jumps at cell faces; zeros where d >= 0)."""
    inside, base, sx, sy, tx, ty, tz, inv = _cell(offset, shape, origin, spacing, qx, qy, qz)
    if not inside:
        return OUTSIDE_MM, 0.0, 0.0, 0.0
    d = _trilinear(values, base, sx, sy, tx, ty, tz)
    if d >= 0.0:
        return d, 0.0, 0.0, 0.0
    gx = gy = gz = 0.0
    for di in range(2):
        wx = tx if di else 1.0 - tx
        for dj in range(2):
            wy = wx * (ty if dj else 1.0 - ty)
            n = base + di * sx + dj * sy
            gx += wy * ((1.0 - tz) * normals[n, 0] + tz * normals[n + 1, 0])
            gy += wy * ((1.0 - tz) * normals[n, 1] + tz * normals[n + 1, 1])
            gz += wy * ((1.0 - tz) * normals[n, 2] + tz * normals[n + 1, 2])
    return d, gx, gy, gz


NORMAL_SCALE = 127.0  # unit normals stored as int8 components


def nodal_normals(values, offsets, shape, spacing):
    """Unit direction of the central-difference gradient (one-sided at the borders) at every node of
    the flattened grids, as int8 components × 127 in rows of 4 (n, 4) (the fourth 0): a 0.5° quantization,
    4 bytes a node so the look-ups stay in cache; only the direction of a contact force is taken from it."""
    out = np.zeros((len(values), 4), np.int8)
    for b in range(len(shape)):
        n = int(np.prod(shape[b]))
        if n == 0 or np.min(shape[b]) < 2:
            continue
        grid = np.asarray(values[offsets[b] : offsets[b] + n], np.float64).reshape(tuple(shape[b]))
        g = np.stack([c.ravel() for c in np.gradient(grid, float(spacing[b]))], axis=1)
        norm = np.linalg.norm(g, axis=1, keepdims=True)
        unit = np.divide(g, norm, out=np.zeros_like(g), where=norm > 0)
        out[offsets[b] : offsets[b] + n, :3] = np.rint(unit * NORMAL_SCALE).astype(np.int8)
    return out


@njit(cache=True, error_model="numpy")
def law_pressure(law, e):
    """Pressure (MPa) of the tri-linear law [e1, e2, k1, k2, k3] at strain e."""
    if e <= 0.0:
        return 0.0
    e1, e2, k1, k2, k3 = law[0], law[1], law[2], law[3], law[4]
    if e <= e1:
        return k1 * e
    if e <= e2:
        return k1 * e1 + k2 * (e - e1)
    return k1 * e1 + k2 * (e2 - e1) + k3 * (e - e2)


@njit(cache=True, error_model="numpy")
def law_slope(law, e):
    """dp/de (MPa per unit strain) of the tri-linear law at strain e (0 out of contact)."""
    if e <= 0.0:
        return 0.0
    if e <= law[0]:
        return law[2]
    if e <= law[1]:
        return law[3]
    return law[4]


@njit(cache=True, error_model="numpy")
def law_energy(law, e):
    """Strain energy density ∫ p de (MPa) of the law from 0 to strain e."""
    if e <= 0.0:
        return 0.0
    e1, e2, k1, k2, k3 = law[0], law[1], law[2], law[3], law[4]
    if e <= e1:
        return 0.5 * k1 * e * e
    w = 0.5 * k1 * e1 * e1
    p1 = k1 * e1
    if e <= e2:
        return w + p1 * (e - e1) + 0.5 * k2 * (e - e1) ** 2
    w += p1 * (e2 - e1) + 0.5 * k2 * (e2 - e1) ** 2
    p2 = p1 + k2 * (e2 - e1)
    return w + p2 * (e - e2) + 0.5 * k3 * (e - e2) ** 2
