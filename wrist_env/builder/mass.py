"""Rigid-body mass properties of bones from their closed surfaces."""

from __future__ import annotations

import numpy as np
import trimesh
from numpy.typing import ArrayLike

BONE_DENSITY = 1.5e-9
"""Whole-bone density of the carpals, t/mm³ (1.5 g/cm³: cortical shell over trabecular core)."""


def mass_properties(
    vertices: ArrayLike, faces: ArrayLike, density: float = BONE_DENSITY
) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass (t), centre of mass (3,) mm and inertia (3, 3) t·mm² about it, RCS axes."""
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.density = density
    return float(mesh.mass), np.asarray(mesh.center_mass), np.asarray(mesh.moment_inertia)
