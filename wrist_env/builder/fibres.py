"""Ligament geometry: fibre bundles and the RSC membrane (preprint 2.2.1.3, Table 2).

A bundle's fibre endpoints are K-means centres of each attachment patch,
snapped to distinct patch points (so they lie on the bone surface), and paired
by the Kuhn–Munkres algorithm (minimum total length). The mean fibre length is
the bundle's reference length.

The radioscaphocapitate (RSC) ligament is a 2D membrane: a quad grid of nodes
from the radius to the capitate over the scaphoid waist, its first row on the
radius, its last row on the capitate, with connectors along and across.
"""

from __future__ import annotations

from dataclasses import dataclass

import igl
import numpy as np
import trimesh
from numpy.typing import ArrayLike
from scipy.interpolate import make_interp_spline
from scipy.optimize import linear_sum_assignment
from scipy.spatial import cKDTree
from scipy.spatial.distance import cdist
from sklearn.cluster import KMeans

from wrist_env.errors import BuildError, InputError

ALONG, ACROSS = 0, 1


@dataclass(frozen=True)
class Bundle:
    """One ligament bundle of straight fibres; fibre i runs origin[i] → insertion[i].

    origin, insertion: arrays of shape (n, 3), mm. origin_index, insertion_index:
    arrays of shape (n,), int64, vertex ids on the origin and insertion bone meshes.
    reference_length_mm: mean fibre length, mm.
    """

    name: str
    origin: np.ndarray
    insertion: np.ndarray
    origin_index: np.ndarray
    insertion_index: np.ndarray
    reference_length_mm: float


@dataclass(frozen=True)
class Membrane:
    """The RSC membrane: a quad grid of nodes, node id = row * n_across + column.

    nodes: array of shape (n_along * n_across, 3), mm. shape: (n_along, n_across).
    radius_nodes, capitate_nodes: bool arrays of shape (n_along * n_across,): the
    first row (on the radius) and the last row (on the capitate); the rest are free.
    connectors: array of shape (k, 2), int64 node pairs. connector_kind: array of
    shape (k,), int8, 0 along (radius → capitate), 1 across.
    reference_length_mm: array of shape (k,), mm, neutral connector lengths.
    """

    nodes: np.ndarray
    shape: tuple[int, int]
    radius_nodes: np.ndarray
    capitate_nodes: np.ndarray
    connectors: np.ndarray
    connector_kind: np.ndarray
    reference_length_mm: np.ndarray


def _points(points, name: str, at_least: int) -> np.ndarray:
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise InputError(f"{name} must have shape (n, 3), but got {p.shape}.")
    if not np.isfinite(p).all():
        raise InputError(f"{name} must be finite, but {int((~np.isfinite(p)).any(axis=1).sum())} points are not.")
    n_unique = len(np.unique(p, axis=0))
    if n_unique < at_least:
        raise InputError(f"{name} must hold at least {at_least} distinct points, but holds {n_unique}.")
    return p


def _snap_distinct(targets: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Indices (m,) of distinct `points` nearest to each target, in target order.

    A target whose nearest point is taken gets the next nearest unused one.
    """
    unique, first = np.unique(points, axis=0, return_index=True)
    k = min(len(targets), len(unique))
    _, near = cKDTree(unique).query(targets, k=k)
    near = near.reshape(len(targets), k)
    used, out = set(), []
    for row in near:
        j = next(int(j) for j in row if j not in used)
        used.add(j)
        out.append(first[j])
    return np.asarray(out, dtype=np.int64)


def fibre_endpoints(patch_points: ArrayLike, n_fibres: int, seed: int | None) -> tuple[np.ndarray, np.ndarray]:
    """Fibre endpoints on one attachment patch: K-means centres snapped to distinct patch points.

    patch_points: array of shape (m, 3), mm. Returns (points (n, 3) mm, index (n,)
    int64 into patch_points).
    """
    if not (isinstance(n_fibres, (int, np.integer)) and n_fibres >= 1):
        raise InputError(f"`n_fibres >= 1` (an integer) must hold, but got {n_fibres=}.")
    p = _points(patch_points, "patch_points", n_fibres)
    state = int(np.random.default_rng(seed).integers(2**31 - 1))
    unique = np.unique(p, axis=0)
    centres = KMeans(n_clusters=int(n_fibres), n_init=8, random_state=state).fit(unique).cluster_centers_
    index = _snap_distinct(centres, p)
    return p[index].copy(), index


def pair_fibres(origins: ArrayLike, insertions: ArrayLike) -> np.ndarray:
    """Minimum-total-length pairing (Kuhn–Munkres): insertions[perm[i]] pairs with origins[i].

    origins, insertions: arrays of shape (n, 3), mm. Returns perm (n,), int64.
    """
    o, i = np.asarray(origins, dtype=np.float64), np.asarray(insertions, dtype=np.float64)
    if o.ndim != 2 or o.shape[1] != 3 or o.shape != i.shape:
        raise InputError(f"origins and insertions must have the same shape (n, 3), but got {o.shape} and {i.shape}.")
    rows, cols = linear_sum_assignment(cdist(o, i))
    perm = np.empty(len(o), dtype=np.int64)
    perm[rows] = cols
    return perm


def build_bundle(
    name: str,
    origin_points: ArrayLike,
    insertion_points: ArrayLike,
    n_fibres: int,
    seed: int | None,
    origin_vertex_ids: ArrayLike | None = None,
    insertion_vertex_ids: ArrayLike | None = None,
) -> Bundle:
    """A bundle of n_fibres fibres between two attachment patches.

    origin_points, insertion_points: arrays of shape (m, 3), mm, patch points.
    origin_vertex_ids, insertion_vertex_ids: arrays of shape (m,), bone-mesh vertex
    id of each patch point (default: the patch index).
    """
    ends = []
    seeds = np.random.default_rng(seed).integers(2**31 - 1, size=2)
    for points, ids, what, s in (
        (origin_points, origin_vertex_ids, "origin", int(seeds[0])),
        (insertion_points, insertion_vertex_ids, "insertion", int(seeds[1])),
    ):
        try:
            pts, idx = fibre_endpoints(points, n_fibres, s)
        except InputError as err:
            raise InputError(f"ligament {name} ({what}): {err}") from err
        if ids is not None:
            ids = np.asarray(ids, dtype=np.int64)
            if ids.shape != (len(np.asarray(points)),):
                raise InputError(
                    f"ligament {name}: {what}_vertex_ids must have shape ({len(np.asarray(points))},), "
                    f"but got {ids.shape}."
                )
            idx = ids[idx]
        ends.append((pts, idx))
    (o, oi), (ins, ii) = ends
    perm = pair_fibres(o, ins)
    ins, ii = ins[perm], ii[perm]
    length = float(np.linalg.norm(ins - o, axis=1).mean())
    return Bundle(name=name, origin=o, insertion=ins, origin_index=oi, insertion_index=ii, reference_length_mm=length)


def _ordered_across(points: np.ndarray, n: int) -> np.ndarray:
    """n distinct patch points (n, 3) evenly spaced along the patch's principal axis."""
    centre = points.mean(axis=0)
    axis = np.linalg.svd(points - centre, full_matrices=False)[2][0]
    t = (points - centre) @ axis
    targets = centre + np.linspace(t.min(), t.max(), n)[:, None] * axis
    return points[_snap_distinct(targets, points)]


def _outward(mesh: trimesh.Trimesh, points: np.ndarray):
    """Signed distance (m,) mm (negative inside), closest points (m, 3) and outward unit directions (m, 3)."""
    s, face, closest, _ = igl.signed_distance(
        points, np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64)
    )
    d = points - closest
    norm = np.linalg.norm(d, axis=1)
    away = np.where(s < 0, -1.0, 1.0)[:, None] * d / np.maximum(norm, 1e-300)[:, None]
    direction = np.where((norm > 1e-9)[:, None], away, mesh.face_normals[face])
    return s, closest, direction


def build_membrane(
    radius_points: ArrayLike,
    capitate_points: ArrayLike,
    scaphoid_mesh: trimesh.Trimesh,
    n_along: int = 9,
    n_across: int = 5,
    lift_mm: float = 0.5,
) -> Membrane:
    """The RSC membrane from the radius patch over the scaphoid waist to the capitate patch.

    radius_points, capitate_points: arrays of shape (m, 3), mm, attachment patches.
    scaphoid_mesh: watertight, outward-oriented scaphoid surface, mm. Interior nodes
    keep at least lift_mm (mm) from the scaphoid.
    """
    if not (isinstance(n_along, (int, np.integer)) and n_along >= 3):
        raise InputError(f"`n_along >= 3` (an integer) must hold, but got {n_along=}.")
    if not (isinstance(n_across, (int, np.integer)) and n_across >= 2):
        raise InputError(f"`n_across >= 2` (an integer) must hold, but got {n_across=}.")
    if not (np.isfinite(lift_mm) and lift_mm > 0):
        raise InputError(f"`lift_mm > 0` must hold, but got {lift_mm=}.")
    if len(scaphoid_mesh.faces) == 0:
        raise InputError("scaphoid_mesh must have faces, but has none.")
    r = _ordered_across(_points(radius_points, "radius_points", n_across), n_across)
    c = _ordered_across(_points(capitate_points, "capitate_points", n_across), n_across)
    if np.linalg.norm(c - r, axis=1).sum() > np.linalg.norm(c[::-1] - r, axis=1).sum():
        c = c[::-1]  # principal axes point opposite ways: don't cross the curves

    _, waist, direction = _outward(scaphoid_mesh, 0.5 * (r + c))
    waist = waist + lift_mm * direction
    dense = np.linspace(0.0, 1.0, 257)
    nodes = np.empty((n_along, n_across, 3))
    for j in range(n_across):
        via = np.stack([r[j], waist[j], c[j]])
        chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(via, axis=0), axis=1))])
        if chord[-1] <= 0 or np.diff(chord).min() <= 0:
            raise BuildError(f"RSC curve {j} is degenerate: radius, waist and capitate points {via.tolist()} coincide.")
        spline = make_interp_spline(chord / chord[-1], via, k=2)
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(spline(dense), axis=0), axis=1))])
        nodes[:, j] = spline(np.interp(np.linspace(0.0, arc[-1], n_along), arc, dense))
    nodes[0], nodes[-1] = r, c

    interior = nodes[1:-1].reshape(-1, 3)
    for _ in range(8):  # a push off one face can land near another in a concavity
        s, closest, direction = _outward(scaphoid_mesh, interior)
        near = s < lift_mm * (1 - 1e-9)
        if not near.any():
            break
        interior[near] = closest[near] + lift_mm * direction[near]
    nodes[1:-1] = interior.reshape(n_along - 2, n_across, 3)
    nodes = nodes.reshape(-1, 3)

    ids = np.arange(n_along * n_across).reshape(n_along, n_across)
    along = np.stack([ids[:-1].ravel(), ids[1:].ravel()], axis=1)
    across = np.stack([ids[:, :-1].ravel(), ids[:, 1:].ravel()], axis=1)
    connectors = np.vstack([along, across]).astype(np.int64)
    kind = np.concatenate([np.full(len(along), ALONG), np.full(len(across), ACROSS)]).astype(np.int8)
    length = np.linalg.norm(nodes[connectors[:, 1]] - nodes[connectors[:, 0]], axis=1)
    if (length <= 0).any():
        raise BuildError(f"RSC membrane has {int((length <= 0).sum())} zero-length connectors.")
    row = ids // n_across
    return Membrane(
        nodes=nodes,
        shape=(int(n_along), int(n_across)),
        radius_nodes=(row == 0).ravel(),
        capitate_nodes=(row == n_along - 1).ravel(),
        connectors=connectors,
        connector_kind=kind,
        reference_length_mm=length,
    )
