"""Non-rigid registration of the annotated template onto a participant's bone.

The template bone is first aligned to the participant's by a similarity
transform (rotation, translation, isotropic scale: ICP from the centroid
offset, since participants are near the template), then registered
non-rigidly with the optimal-step non-rigid ICP of Amberg et al. 2007
(`trimesh.registration.nricp_amberg`). The result is the template's topology
laid onto the participant's surface; annotations (vertex masks, points) are
carried over through it.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import igl
import numpy as np
import trimesh
from numpy.typing import ArrayLike
from scipy.spatial import cKDTree

from wrist_env.errors import InputError, MeshError
from wrist_env.io import fields_equal

# Non-rigid ICP stages (stiffness ws, landmark weight wl, normal weight wn,
# max iterations), stiff to flexible. Stiffness is in trimesh's units (source
# normalized to its bounding-box diagonal). On myo-sim carpal bones under a
# 1.05 scale and 2 mm / 10 mm RBF warps, this recovered the true vertex
# positions better than trimesh's default schedule (mean error 0.25–0.39 vs
# 0.23–0.72 mm over four cases) at about the same cost (~2–4 s per bone).
STEPS = ((1.0, 0.0, 0.5, 10), (0.1, 0.0, 0.5, 10), (0.01, 0.0, 0.5, 10))
ICP_SAMPLES = 600  # template vertices drawn (with the seed) for the similarity ICP
SIZE_RATIO = (0.5, 2.0)  # allowed participant / template size (bounding-box diagonal)


@dataclass(frozen=True, eq=False)
class MorphResult:
    """The template's topology laid onto a participant's bone.

    vertices: array of shape (n, 3), mm, morphed template vertices.
    surface_error_mm: array of shape (n,), distance of each morphed vertex to the target surface.
    error_mean_mm, error_max_mm: mean and maximum of `surface_error_mm`.
    alignment: array of shape (4, 4), the similarity transform (mm) applied before the non-rigid stage.
    seconds: wall time of the morph (not compared for equality).
    """

    vertices: np.ndarray
    surface_error_mm: np.ndarray
    error_mean_mm: float
    error_max_mm: float
    alignment: np.ndarray
    seconds: float

    def __eq__(self, other) -> bool:
        if not isinstance(other, MorphResult):
            return NotImplemented
        return fields_equal(
            self, other, ("error_mean_mm", "error_max_mm"), ("vertices", "surface_error_mm", "alignment")
        )

    __hash__ = None


def _mesh(vertices, faces, name: str) -> tuple[np.ndarray, np.ndarray]:
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    if v.ndim != 2 or v.shape[1] != 3:
        raise MeshError(f"`{name}_vertices` must have shape (n, 3), but got shape {v.shape}.")
    if f.ndim != 2 or f.shape[1] != 3 or (f.size and not np.issubdtype(f.dtype, np.integer)):
        raise MeshError(f"`{name}_faces` must be integers of shape (m, 3), but got shape {f.shape} of {f.dtype}.")
    if len(v) == 0 or len(f) == 0:
        raise MeshError(f"the {name} mesh must have vertices and faces, but got {len(v)} vertices and {len(f)} faces.")
    if not np.isfinite(v).all():
        bad = np.flatnonzero(~np.isfinite(v).all(axis=1))
        raise MeshError(
            f"`{name}_vertices` must be finite, but vertex {bad[0]} is {v[bad[0]].tolist()} "
            f"({len(bad)} non-finite vertices)."
        )
    if f.min() < 0 or f.max() >= len(v):
        raise MeshError(f"`{name}_faces` must index vertices 0..{len(v) - 1}, but got indices {f.min()}..{f.max()}.")
    return v, f.astype(np.int64)


def _similarity(template: trimesh.Trimesh, target: trimesh.Trimesh, seed: int | None) -> np.ndarray:
    """Similarity transform (4, 4) taking the template near the target (ICP with scale)."""
    rng = np.random.default_rng(seed)
    n = len(template.vertices)
    sample = template.vertices[np.sort(rng.choice(n, min(n, ICP_SAMPLES), replace=False))]
    initial = np.eye(4)
    initial[:3, 3] = target.centroid - template.centroid
    matrix, _, _ = trimesh.registration.icp(
        sample, target, initial=initial, threshold=1e-9, max_iterations=200, scale=True, reflection=False
    )
    return matrix


def morph(
    template_vertices: ArrayLike,
    template_faces: ArrayLike,
    target_vertices: ArrayLike,
    target_faces: ArrayLike,
    *,
    steps: Sequence[tuple[float, float, float, int]] | None = None,
    seed: int | None = 0,
) -> MorphResult:
    """Register the template bone onto the target bone (both in mm).

    template_vertices: array of shape (n, 3), mm; template_faces: (m, 3) int.
    target_vertices: array of shape (p, 3), mm; target_faces: (q, 3) int.
    steps: non-rigid ICP stages `(ws, wl, wn, max_iter)` (default `STEPS`).
    seed: draws the template vertices used by the similarity ICP.
    """
    start = time.perf_counter()
    tv, tf = _mesh(template_vertices, template_faces, "template")
    pv, pf = _mesh(target_vertices, target_faces, "target")
    template = trimesh.Trimesh(tv, tf, process=False)
    target = trimesh.Trimesh(pv, pf, process=False)
    ratio = target.scale / template.scale
    if not SIZE_RATIO[0] <= ratio <= SIZE_RATIO[1]:
        raise MeshError(
            f"the target must be the template's bone in mm: its size (bounding-box diagonal) must be "
            f"{SIZE_RATIO[0]}–{SIZE_RATIO[1]} times the template's, but got {ratio:.4g} "
            f"({target.scale:.4g} vs {template.scale:.4g})."
        )
    alignment = _similarity(template, target, seed)
    aligned = trimesh.Trimesh(trimesh.transform_points(tv, alignment), tf, process=False)
    stages = [list(s) for s in (STEPS if steps is None else steps)]
    vertices = np.asarray(trimesh.registration.nricp_amberg(aligned, target, steps=stages), dtype=np.float64)
    error = np.sqrt(igl.point_mesh_squared_distance(vertices, pv, pf)[0])
    vertices.setflags(write=False)
    error.setflags(write=False)
    alignment.setflags(write=False)
    return MorphResult(
        vertices=vertices,
        surface_error_mm=error,
        error_mean_mm=float(error.mean()),
        error_max_mm=float(error.max()),
        alignment=alignment,
        seconds=time.perf_counter() - start,
    )


def transfer_mask(result: MorphResult, template_mask: ArrayLike, target_vertices: ArrayLike) -> np.ndarray:
    """Bool mask of shape (p,) on the target vertices (p, 3), mm: the mask of each one's nearest morphed vertex.

    template_mask: bool array of shape (n,) on the template vertices.
    """
    mask = np.asarray(template_mask)
    if mask.shape != (len(result.vertices),) or mask.dtype != bool:
        raise InputError(
            f"`template_mask` must be bool of shape ({len(result.vertices)},), "
            f"but got {mask.dtype} of shape {mask.shape}."
        )
    p = np.asarray(target_vertices, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or not np.isfinite(p).all():
        raise InputError(
            f"`target_vertices` must be finite with shape (p, 3), but got shape {p.shape}"
            f"{'' if p.ndim != 2 or p.shape[1] != 3 else ' with non-finite values'}."
        )
    _, nearest = cKDTree(result.vertices).query(p)
    return mask[nearest]


def transfer_points(result: MorphResult, template_vertex_ids: ArrayLike) -> np.ndarray:
    """Morphed positions, array of shape (k, 3), mm, of template vertices given by ids of shape (k,)."""
    ids = np.asarray(template_vertex_ids)
    n = len(result.vertices)
    if ids.ndim != 1 or (ids.size and not np.issubdtype(ids.dtype, np.integer)):
        raise InputError(
            f"`template_vertex_ids` must be integers of shape (k,), but got {ids.dtype} of shape {ids.shape}."
        )
    if ids.size and (ids.min() < 0 or ids.max() >= n):
        raise InputError(f"`template_vertex_ids` must lie in 0..{n - 1}, but got {ids.min()}..{ids.max()}.")
    return result.vertices[ids.astype(np.int64)]
