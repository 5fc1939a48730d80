"""Signed-distance grids of bone-plus-cartilage surfaces, for contact look-ups.

Each grid holds the signed distance (mm, positive outside) to one bone's
displaced surface (bone with its cartilage), sampled on a regular grid in
that bone's own frame (the RCS in the neutral pose). Exact distances come
from libigl, signed by the fast winding number (robust where a displaced
cartilage rim folds); values are clamped to ± `band_mm`.
"""

from __future__ import annotations

from dataclasses import dataclass

import igl
import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True)
class DistanceGrid:
    """Signed distance on a regular grid.

    origin: array of shape (3,), mm, position of node (0, 0, 0).
    spacing_mm: node spacing.
    values: array of shape (nx, ny, nz), float32, mm (positive outside).
    """

    origin: np.ndarray
    spacing_mm: float
    values: np.ndarray


def signed_distance_grid(
    vertices: ArrayLike, faces: ArrayLike, *, spacing_mm: float = 0.5, margin_mm: float = 3.0, band_mm: float = 5.0
) -> DistanceGrid:
    """Grid over the surface's bounding box grown by `margin_mm`, at `spacing_mm`."""
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    f = np.ascontiguousarray(faces, dtype=np.int64)
    lo = v.min(axis=0) - margin_mm
    shape = np.ceil((v.max(axis=0) + margin_mm - lo) / spacing_mm).astype(int) + 1
    axes = [lo[i] + spacing_mm * np.arange(shape[i]) for i in range(3)]
    points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    s = igl.signed_distance(points, v, f, sign_type=igl.SignedDistanceType.SIGNED_DISTANCE_TYPE_FAST_WINDING_NUMBER)[0]
    values = np.clip(s, -band_mm, band_mm).reshape(shape).astype(np.float32)
    return DistanceGrid(origin=lo, spacing_mm=float(spacing_mm), values=values)


def trilinear(grid: DistanceGrid, points: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Trilinear value (mm) and gradient of shape (n, 3) at `points` of shape (n, 3).

    Points outside the grid are clamped to its boundary cells (reference
    implementation for tests; the solver has its own Numba kernel).
    """
    p = (np.asarray(points, dtype=np.float64) - grid.origin) / grid.spacing_mm
    shape = np.array(grid.values.shape)
    i = np.clip(np.floor(p).astype(int), 0, shape - 2)
    t = np.clip(p - i, 0.0, 1.0)
    V = grid.values.astype(np.float64)
    value = np.zeros(len(p))
    grad = np.zeros((len(p), 3))
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                c = V[i[:, 0] + dx, i[:, 1] + dy, i[:, 2] + dz]
                wx = t[:, 0] if dx else 1 - t[:, 0]
                wy = t[:, 1] if dy else 1 - t[:, 1]
                wz = t[:, 2] if dz else 1 - t[:, 2]
                value += c * wx * wy * wz
                grad[:, 0] += c * (1 if dx else -1) * wy * wz
                grad[:, 1] += c * wx * (1 if dy else -1) * wz
                grad[:, 2] += c * wx * wy * (1 if dz else -1)
    return value, grad / grid.spacing_mm
