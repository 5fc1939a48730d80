"""Minimal synthetic `Model`s for solver verification: flat slabs, patches, single fibres.

Everything not given is empty: no meshes, no grids, no contact samples, no
fibres, no membrane. Bodies and pairs are indexed as in `wrist_env.model`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from wrist_env.model import BONES, PAIRS, Model, offsets


@dataclass(frozen=True)
class Grid:
    """A bone's signed-distance grid: origin (3,) mm, spacing mm, values (nx, ny, nz) mm."""

    origin: np.ndarray
    spacing: float
    values: np.ndarray


@dataclass(frozen=True)
class Patch:
    """Contact samples: points (n, 3) mm, normals (n, 3), area (n,) mm², total thickness (n,) mm."""

    points: np.ndarray
    normals: np.ndarray
    area: np.ndarray
    thickness: np.ndarray


@dataclass(frozen=True)
class Fibre:
    """One ligament fibre: Table 2 ligament index, origin and insertion bone, points (3,) mm."""

    ligament: int
    origin_bone: int
    insertion_bone: int
    origin: np.ndarray
    insertion: np.ndarray


def half_space_grid(lo, hi, spacing: float, point, normal) -> Grid:
    """Grid over the box [lo, hi] (mm) of the signed distance (q − point)·normal to a plane.

    normal (3,): unit outward normal of the body. A linear field, so trilinear
    interpolation reproduces it exactly.
    """
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    shape = np.floor((hi - lo) / spacing + 1e-9).astype(int) + 1
    axes = [lo[i] + spacing * np.arange(shape[i]) for i in range(3)]
    q = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    return Grid(lo, float(spacing), (q - np.asarray(point, float)) @ np.asarray(normal, float))


def square_patch(centre, half_width: float, spacing: float, thickness: float, normal) -> Patch:
    """Samples at the cell centres of a square in the x–z plane through `centre` (3,) mm.

    Cells of side `spacing` (mm), area spacing² each, all of total thickness `thickness` (mm).
    """
    n = int(round(2 * half_width / spacing))
    u = -half_width + spacing * (np.arange(n) + 0.5)
    x, z = np.meshgrid(u, u, indexing="ij")
    points = np.asarray(centre, float) + np.stack([x.ravel(), np.zeros(x.size), z.ravel()], axis=1)
    return _patch(points, np.tile(np.asarray(normal, float), (len(points), 1)), spacing**2, thickness)


def spherical_cap(apex, radius: float, cap_radius: float, spacing: float, thickness: float) -> Patch:
    """Samples on a sphere of `radius` (mm) whose apex (3,) mm points along +y.

    Samples lie above the nodes of an x–z grid of `spacing` (mm) within
    `cap_radius` (mm) of the apex, one node at the apex; each carries the
    projected area spacing² (mm²).
    """
    n = int(np.floor(cap_radius / spacing))
    u = spacing * np.arange(-n, n + 1)
    x, z = (a.ravel() for a in np.meshgrid(u, u, indexing="ij"))
    keep = x**2 + z**2 <= cap_radius**2
    x, z = x[keep], z[keep]
    centre = np.asarray(apex, float) - [0.0, radius, 0.0]
    points = centre + np.stack([x, np.sqrt(radius**2 - x**2 - z**2), z], axis=1)
    return _patch(points, (points - centre) / radius, spacing**2, thickness)


def _patch(points, normals, area: float, thickness: float) -> Patch:
    n = len(points)
    return Patch(points, normals, np.full(n, float(area)), np.full(n, float(thickness)))


def box_inertia(mass: float, size) -> np.ndarray:
    """Inertia (3, 3) t·mm² about the centre of a solid box of `mass` (t) and edge lengths `size` (3,) mm."""
    a, b, c = np.asarray(size, float) ** 2
    return mass / 12.0 * np.diag([b + c, a + c, a + b])


IDLE_COM_MM = (1000.0, 0.0, 0.0)
"""Where a body a synthetic model does not give sits: far from everything, so nothing acts on it."""


def _all_bodies(mass, com, inertia):
    """mass, com, inertia padded to every body of `BONES` (the fixtures give the first five): an idle body
    of 1 mg at `IDLE_COM_MM` (free bodies need a mass: it stays at rest, no force reaches it)."""
    mass, com, inertia = (np.asarray(a, float) for a in (mass, com, inertia))
    extra = len(BONES) - len(mass)
    if extra > 0:
        mass = np.concatenate([mass, np.full(extra, 1e-9)])
        com = np.vstack([com, np.tile(IDLE_COM_MM, (extra, 1))])
        inertia = np.concatenate([inertia, np.tile(1e-9 * np.eye(3), (extra, 1, 1))])
    return mass, com, inertia


def model(
    *,
    mass,
    com,
    inertia,
    law,
    grids: dict | None = None,
    patches: dict | None = None,
    fibres=(),
    name: str = "synthetic",
) -> Model:
    """A `Model` from bodies, contact and fibres; everything else empty.

    mass (5,) t; com (5, 3) mm; inertia (5, 3, 3) t·mm²; law (5,) tri-linear
    [e1, e2, k1, k2, k3]; grids {bone index: Grid}; patches {pair index: Patch};
    fibres: a sequence of `Fibre`.
    """
    grids, patches = grids or {}, patches or {}
    mass, com, inertia = _all_bodies(mass, com, inertia)
    empty_grid = Grid(np.zeros(3), 0.0, np.zeros((0, 0, 0)))
    g = [grids.get(b, empty_grid) for b in range(len(BONES))]
    empty_patch = _patch(np.zeros((0, 3)), np.zeros((0, 3)), 0.0, 0.0)
    p = [patches.get(i, empty_patch) for i in range(len(PAIRS))]
    fib = list(fibres)
    lig = np.array([f.ligament for f in fib], np.int64).reshape(-1)
    length = np.array([np.linalg.norm(np.subtract(f.insertion, f.origin)) for f in fib]).reshape(-1)
    count = np.bincount(lig, minlength=11)
    reference_length = np.bincount(lig, weights=length, minlength=11) / np.maximum(count, 1)
    zero_bones = np.zeros(len(BONES) + 1, np.int64)
    return Model(
        name=name,
        source_hash="synthetic",
        vertices=np.zeros((0, 3)),
        vertex_offsets=zero_bones,
        faces=np.zeros((0, 3), np.int64),
        face_offsets=zero_bones,
        vertex_part=np.zeros(0, np.int64),
        thickness=np.zeros(0),
        mass=np.asarray(mass, float),
        com=np.asarray(com, float),
        inertia=np.asarray(inertia, float),
        centroid=np.asarray(com, float),
        grid_origin=np.array([x.origin for x in g], float),
        grid_spacing=np.array([x.spacing for x in g], float),
        grid_shape=np.array([x.values.shape for x in g], np.int64),
        grid_values=np.concatenate([x.values.ravel() for x in g]).astype(np.float32),
        grid_offsets=offsets([x.values.size for x in g]),
        sample_points=np.concatenate([x.points for x in p]),
        sample_normals=np.concatenate([x.normals for x in p]),
        sample_area=np.concatenate([x.area for x in p]),
        sample_thickness=np.concatenate([x.thickness for x in p]),
        sample_offsets=offsets([len(x.points) for x in p]),
        contact_law=np.asarray(law, float),
        fibre_ligament=lig,
        fibre_bones=np.array([[f.origin_bone, f.insertion_bone] for f in fib], np.int64).reshape(-1, 2),
        fibre_origin=np.array([f.origin for f in fib], float).reshape(-1, 3),
        fibre_insertion=np.array([f.insertion for f in fib], float).reshape(-1, 3),
        reference_length=reference_length,
        membrane_nodes=np.zeros((0, 3)),
        membrane_bone=np.zeros(0, np.int64),
        membrane_connectors=np.zeros((0, 2), np.int64),
        membrane_kind=np.zeros(0, np.int64),
        membrane_length=np.zeros(0),
    )


def rotation_90(axis: int, quarter_turns: int = 1) -> np.ndarray:
    """Rotation (3, 3) by quarter_turns × 90° about coordinate `axis` (0, 1, 2): a signed permutation."""
    c, s = [(1, 0), (0, 1), (-1, 0), (0, -1)][quarter_turns % 4]
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    Q = np.eye(3)
    Q[i, i], Q[i, j], Q[j, i], Q[j, j] = c, -s, s, c
    return Q


def transformed(model: Model, Q, t) -> Model:
    """The same model moved rigidly by x ↦ Q x + t (mm): every position, direction, inertia and grid.

    Q (3, 3) must be a proper rotation that permutes the coordinate axes (entries
    0 and ±1, det +1, e.g. `rotation_90`), so each axis-aligned signed-distance
    grid maps onto an axis-aligned grid exactly: its values are permuted
    (transposed and flipped), never resampled. t (3,) mm.
    """
    Q = np.asarray(Q, float)
    t = np.asarray(t, float)
    if not (
        np.all(np.isin(Q, (-1.0, 0.0, 1.0))) and np.allclose(Q @ Q.T, np.eye(3)) and np.isclose(np.linalg.det(Q), 1.0)
    ):
        raise ValueError(f"Q must be a proper signed permutation matrix, got {Q.tolist()}")
    perm = np.argmax(np.abs(Q), axis=1)  # new axis m is old axis perm[m] ...
    sign = Q[np.arange(3), perm]  # ... times sign[m]

    def points(p):
        return np.asarray(p, float) @ Q.T + t

    def directions(d):
        return np.asarray(d, float) @ Q.T

    origin, shape, values = [], [], []
    for b in range(len(BONES)):
        n = model.grid_shape[b]
        g = model.grid_values[model.grid_offsets[b] : model.grid_offsets[b + 1]].reshape(n)
        g = np.transpose(g, perm)
        g = np.flip(g, axis=tuple(int(m) for m in np.flatnonzero(sign < 0)))
        o = np.empty(3)
        for m in range(3):
            k = perm[m]
            o[m] = t[m] + (
                model.grid_origin[b, k]
                if sign[m] > 0
                else -(model.grid_origin[b, k] + model.grid_spacing[b] * (n[k] - 1))
            )
        origin.append(o if g.size else model.grid_origin[b])
        shape.append(g.shape)
        values.append(np.ascontiguousarray(g).ravel())
    return replace(
        model,
        name=f"{model.name}-moved",
        vertices=points(model.vertices),
        com=points(model.com),
        centroid=points(model.centroid),
        inertia=np.einsum("ij,bjk,lk->bil", Q, model.inertia, Q),
        grid_origin=np.array(origin, float),
        grid_shape=np.array(shape, np.int64).reshape(-1, 3),
        grid_values=np.concatenate(values).astype(np.float32),
        sample_points=points(model.sample_points),
        sample_normals=directions(model.sample_normals),
        fibre_origin=points(model.fibre_origin),
        fibre_insertion=points(model.fibre_insertion),
        membrane_nodes=points(model.membrane_nodes),
    )
