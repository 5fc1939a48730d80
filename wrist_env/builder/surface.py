"""Bone-surface geometry under the cartilage: checked mesh arrays, gaps, smoothing, normals, closed parts.

Vertices are (n, 3) mm, faces (m, 3) vertex indices, a coverage a bool mask over
the vertices. Here: the gap (mm) from covered vertices to an opposing covered
patch, Gaussian-kernel (GRNN) smoothing of values over points, vertex normals
and extrusion directions, the bone-plus-cartilage vertices (mm) of a thickness
per vertex (mm), and the faces of a mesh's closed (watertight) components.
"""

from __future__ import annotations

import igl
import numpy as np
import scipy.sparse
import trimesh
from numpy.typing import ArrayLike
from scipy.spatial import cKDTree

from wrist_env.errors import InputError, MeshError

NORMAL_SMOOTHING_MM = 1.0  # σ of the kernel that smooths extrusion directions over a patch


def _vertices(v, name: str) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise MeshError(f"vertices of {name} must have shape (n, 3), but got {v.shape}.")
    if not np.isfinite(v).all():
        raise MeshError(f"vertices of {name} must be finite, but {int((~np.isfinite(v)).any(axis=1).sum())} are not.")
    return np.ascontiguousarray(v)


def _faces(f, n_vertices: int, name: str) -> np.ndarray:
    f = np.asarray(f)
    if f.ndim != 2 or f.shape[1] != 3 or not np.issubdtype(f.dtype, np.integer):
        raise MeshError(f"faces of {name} must be integers of shape (m, 3), but got {f.dtype} {f.shape}.")
    if f.size and (f.min() < 0 or f.max() >= n_vertices):
        raise MeshError(f"faces of {name} must index 0..{n_vertices - 1}, but span {f.min()}..{f.max()}.")
    return np.ascontiguousarray(f, dtype=np.int64)


def _mask(m, n_vertices: int, name: str) -> np.ndarray:
    m = np.asarray(m)
    if m.dtype != bool or m.shape != (n_vertices,):
        raise InputError(f"coverage of {name} must be bool of shape ({n_vertices},), but got {m.dtype} {m.shape}.")
    return m


def gap_to(
    vertices_a: ArrayLike, cover_a: ArrayLike, vertices_b: ArrayLike, faces_b: ArrayLike, cover_b: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gap from each covered vertex of A to B's covered triangles (all three vertices covered).

    Returns distance (n_cov,) mm, closest points (n_cov, 3) mm and face ids (n_cov,) into `faces_b`.
    """
    va, vb = _vertices(vertices_a, "A"), _vertices(vertices_b, "B")
    fb = _faces(faces_b, len(vb), "B")
    cover_a, cover_b = _mask(cover_a, len(va), "A"), _mask(cover_b, len(vb), "B")
    face_ids = np.flatnonzero(cover_b[fb].all(axis=1))
    if face_ids.size == 0:
        raise InputError(f"`cover_b` must cover at least one triangle of B, but covers 0 of {len(fb)}.")
    d2, i, closest = igl.point_mesh_squared_distance(va[cover_a], vb, fb[face_ids])
    return np.sqrt(d2), closest, face_ids[i]


def grnn_smooth(
    points: ArrayLike, values: ArrayLike, bandwidth_mm: float, query: ArrayLike | None = None
) -> np.ndarray:
    """Generalized regression neural network (Gaussian-kernel Nadaraya–Watson) estimate at `query`.

    points: (n, 3) mm; values: (n,) or (n, k); query: (q, 3) mm, default `points`; bandwidth_mm:
    kernel σ. The kernel is cut at 3σ; a query with no point within 3σ takes its nearest point's
    value. Returns an array of shape (q,) or (q, k).
    """
    if not bandwidth_mm > 0:
        raise InputError(f"`bandwidth_mm > 0` must hold, but got {bandwidth_mm=}.")
    points = _vertices(points, "points")
    values = np.asarray(values, dtype=np.float64)
    if values.ndim not in (1, 2) or len(values) != len(points):
        raise InputError(f"`values` must have shape ({len(points)},) or ({len(points)}, k), but got {values.shape}.")
    query = points if query is None else _vertices(query, "query")
    tree = cKDTree(points)
    pairs = cKDTree(query).sparse_distance_matrix(tree, 3.0 * bandwidth_mm, output_type="ndarray")
    w = np.exp(-0.5 * (pairs["v"] / bandwidth_mm) ** 2)
    kernel = scipy.sparse.csr_array((w, (pairs["i"], pairs["j"])), shape=(len(query), len(points)))
    weight = kernel.sum(axis=1)
    out = kernel @ values
    alone = weight == 0
    out[~alone] = (out[~alone].T / weight[~alone]).T
    if alone.any():
        out[alone] = values[tree.query(query[alone])[1]]
    return out


def vertex_normals(vertices: ArrayLike, faces: ArrayLike) -> np.ndarray:
    """Area-weighted unit vertex normals, shape (n, 3); zero at vertices no face uses."""
    v = _vertices(vertices, "mesh")
    normals = igl.per_vertex_normals(v, _faces(faces, len(v), "mesh"), igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
    return np.nan_to_num(normals)


def extrusion_directions(
    vertices: ArrayLike, faces: ArrayLike, covered: ArrayLike, *, smoothing_mm: float = NORMAL_SMOOTHING_MM
) -> np.ndarray:
    """Unit extrusion directions, shape (n, 3): area-weighted vertex normals, smoothed over the
    covered vertices (bool (n,)) by a Gaussian kernel of σ = `smoothing_mm` (0: no smoothing)."""
    v = _vertices(vertices, "mesh")
    normals = vertex_normals(v, faces)
    covered = np.asarray(covered, dtype=bool)
    if smoothing_mm > 0 and covered.sum() > 1:
        smooth = grnn_smooth(v[covered], normals[covered], smoothing_mm)
        length = np.linalg.norm(smooth, axis=1, keepdims=True)
        normals[covered] = np.where(length > 1e-6, smooth / np.maximum(length, 1e-300), normals[covered])
    return normals


def displaced_vertices(
    vertices: ArrayLike, faces: ArrayLike, thickness: ArrayLike, *, smoothing_mm: float = NORMAL_SMOOTHING_MM
) -> np.ndarray:
    """Bone-plus-cartilage vertices, shape (n, 3), mm: each vertex moved outward by its thickness
    (mm, shape (n,)) along its extrusion direction (see `extrusion_directions`)."""
    v = _vertices(vertices, "mesh")
    t = np.asarray(thickness, dtype=np.float64)
    if t.shape != (len(v),) or not np.isfinite(t).all() or (t < 0).any():
        raise InputError(
            f"thickness must be finite, >= 0 and of shape ({len(v)},), but got shape {t.shape}, "
            f"min {np.min(t, initial=0.0)}."
        )
    return v + t[:, None] * extrusion_directions(v, faces, t > 0, smoothing_mm=smoothing_mm)


def closed_face_mask(faces: ArrayLike) -> np.ndarray:
    """Bool (m,): faces of the watertight connected components of a mesh (components joined across
    edges of exactly two faces; one with an edge of one face, or of more than two, is open)."""
    f = np.asarray(faces, dtype=np.int64)
    component = trimesh.graph.connected_component_labels(trimesh.graph.face_adjacency(f), node_count=len(f))
    edges = np.sort(f[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, edge_id, uses = np.unique(edges, axis=0, return_inverse=True, return_counts=True)
    open_edge = (uses[edge_id.ravel()] != 2).reshape(-1, 3).any(axis=1)
    return ~np.isin(component, component[open_edge])


def closed_faces(faces: ArrayLike) -> np.ndarray:
    """Faces of the watertight connected components of a mesh, shape (k, 3); all faces if none is watertight."""
    f = np.asarray(faces, dtype=np.int64)
    closed = closed_face_mask(f)
    return f[closed] if closed.any() else f
