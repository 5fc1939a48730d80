"""Rebuild the distal radius articular surface (scaphoid and lunate fossae).

The myo-sim radius is coarse (~10 mm edges) and sits 3.4–4.3 mm from the
proximal row. The articular surface is rebuilt as the offset envelope, at the
radiocarpal joint space, of the scaphoid and lunate swept through their
radiocarpal range of motion: each bone turned about the centre of the sphere
that best fits its proximal articular surface, through ± `sweep_deg` of
flexion–extension and of radial–ulnar deviation (no sweep: the moulded fossa
of builder version 1). Turned about its own centre, each bone rolls and
slides in its fossa while the row as a whole is held (swept instead about the
wrist's centre in the capitate head, the row could turn with the capitate at
no cost: in an experiment (issue 10) it lagged the capitate by up to 25° and returned only
past neutral, where a real wrist shows no such hysteresis).
A fossa moulded to the neutral pose alone locks the row (turning the lunate
5° in place overlapped it by 0.18 mm); the swept envelope is the surface the
row can roll and slide in, as the fossae are shaped to let it (the scaphoid
turns ~0.7× and the lunate ~0.45× the capitate's ±40°: Rainbow 2013, so
±20° / ±10° spans the row's radiocarpal arc). Sampled on a regular grid and
extruded into a watertight solid. Coordinates: an RCS-oriented frame (x
volar, y proximal, z radial), mm.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np
import trimesh
from numba import njit
from numpy.typing import ArrayLike
from scipy.spatial import cKDTree

from wrist_env.errors import BuildError

SWEEP_STEPS = (9, 5)  # poses per axis of a swept range


def fossa_points(
    row_meshes: Iterable[trimesh.Trimesh], radius_mesh: trimesh.Trimesh, *, facing: float = 0.3, reach_mm: float = 8.0
) -> np.ndarray:
    """Proximal-row vertices that face the radius: normal·y > `facing`, within `reach_mm` of it.

    Returns array of shape (n, 3), mm.
    """
    radius_tree = cKDTree(trimesh.sample.sample_surface_even(radius_mesh, 20000, seed=0)[0])
    chosen = []
    for mesh in row_meshes:
        faces_up = mesh.vertex_normals[:, 1] > facing
        near, _ = radius_tree.query(mesh.vertices)
        chosen.append(mesh.vertices[faces_up & (near < reach_mm)])
    points = np.concatenate(chosen)
    if len(points) < 50:
        raise BuildError(f"only {len(points)} proximal-row vertices face the radius; cannot rebuild the fossae")
    return points


def offset_heightfield(
    footprint: np.ndarray, row_points: np.ndarray, *, joint_space_mm: float = 1.5, spacing_mm: float = 0.5
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Height y(x, z) of the envelope at `joint_space_mm` proximal to the row.

    The envelope is taken over all `row_points` (so no point comes closer than
    the joint space), on the x–z footprint of `footprint` points dilated by the
    joint space. Returns (xs, zs, height) with height of shape (len(xs), len(zs)),
    NaN off the footprint.
    """
    g = joint_space_mm
    lo = footprint[:, [0, 2]].min(axis=0) - g
    hi = footprint[:, [0, 2]].max(axis=0) + g
    xs = np.arange(lo[0], hi[0] + spacing_mm, spacing_mm)
    zs = np.arange(lo[1], hi[1] + spacing_mm, spacing_mm)
    X, Z = np.meshgrid(xs, zs, indexing="ij")
    grid = np.column_stack([X.ravel(), Z.ravel()])
    on_footprint = cKDTree(footprint[:, [0, 2]]).query(grid)[0] < g
    height = np.full(len(grid), -np.inf)
    reach = int(np.ceil(g / spacing_mm + 0.5))
    cell = np.rint((row_points[:, [0, 2]] - lo) / spacing_mm).astype(np.int64)
    _ball_tops(xs, zs, np.ascontiguousarray(row_points, dtype=np.float64), cell, float(g), reach, height)
    height[~on_footprint | ~np.isfinite(height)] = np.nan
    return xs, zs, fill_creases(height.reshape(X.shape), sigma_cells=1.5)


@njit(cache=True)
def _ball_tops(xs, zs, points, cell, g, reach, height):
    """Raise `height` (len(xs) × len(zs), flat, C order) at every grid node within `g` (mm) of a point's
    (x, z), found among the `reach` cells around the point's own cell (`cell`: (n, 2) node indices), to
    the top of the point's ball there: y + sqrt(g² − d²). Every node is checked against every point in
    reach (a few hundred thousand swept samples × a few hundred nodes each: compiled, not array passes)."""
    nx, nz = len(xs), len(zs)
    inside = g * g * (1 - 1e-9)
    for n in range(points.shape[0]):
        for di in range(-reach, reach + 1):
            i = cell[n, 0] + di
            if i < 0 or i >= nx:
                continue
            dx2 = (xs[i] - points[n, 0]) ** 2
            for dk in range(-reach, reach + 1):
                k = cell[n, 1] + dk
                if k < 0 or k >= nz:
                    continue
                d2 = dx2 + (zs[k] - points[n, 2]) ** 2
                if d2 < inside:
                    top = points[n, 1] + np.sqrt(g * g - d2)
                    if top > height[i * nz + k]:
                        height[i * nz + k] = top


def sphere_centre(points: np.ndarray) -> np.ndarray:
    """Centre (3,) mm of the least-squares sphere through `points` (n, 3)."""
    A = np.column_stack([2.0 * points, np.ones(len(points))])
    b = (points**2).sum(axis=1)
    return np.linalg.lstsq(A, b, rcond=None)[0][:3]


def swept(
    points: np.ndarray,
    centre: ArrayLike,
    flexion_deg: float,
    deviation_deg: float,
    *,
    steps: tuple[int, int] = SWEEP_STEPS,
) -> np.ndarray:
    """`points` (n, 3) turned about `centre` through a grid of flexion (z) and deviation (x)
    angles (deg), stacked: array of shape (n × poses, 3)."""
    from scipy.spatial.transform import Rotation

    out = []
    for f in np.linspace(-flexion_deg, flexion_deg, steps[0]):
        for d in np.linspace(-deviation_deg, deviation_deg, steps[1]):
            R = Rotation.from_euler("ZX", [f, d], degrees=True).as_matrix()
            out.append((points - centre) @ R.T + centre)
    return np.concatenate(out)


def fill_creases(height: np.ndarray, sigma_cells: float = 1.5) -> np.ndarray:
    """Smooth the envelope's creases upwards: max(Gaussian-smoothed height, height), NaN kept.

    The envelope of balls is the lowest surface that keeps the joint space; its
    creases are valleys, so lifting them to the smoothed surface never brings
    the radius closer to the row.
    """
    from scipy import ndimage

    defined = ~np.isnan(height)
    filled = np.where(defined, height, 0.0)
    weight = ndimage.gaussian_filter(defined.astype(float), sigma_cells)
    smooth = ndimage.gaussian_filter(filled, sigma_cells) / np.maximum(weight, 1e-12)
    return np.where(defined, np.maximum(smooth, height), np.nan)


def _largest_component(mask: np.ndarray) -> np.ndarray:
    from scipy import ndimage

    labels, n = ndimage.label(mask)
    if n == 0:
        return mask
    sizes = ndimage.sum(mask, labels, index=np.arange(1, n + 1))
    return labels == (1 + int(np.argmax(sizes)))


def extrude_heightfield(xs: ArrayLike, zs: ArrayLike, height: np.ndarray, *, depth_mm: float = 4.0) -> trimesh.Trimesh:
    """Watertight solid: the heightfield as top (articular) surface, a flat base `depth_mm` proximal.

    Cells with all four corners defined are kept (largest connected patch);
    the base sits at max(height) + depth_mm. Faces wind outward.
    """
    from scipy import ndimage

    defined = ~np.isnan(height)
    cells = defined[:-1, :-1] & defined[1:, :-1] & defined[:-1, 1:] & defined[1:, 1:]
    cells = ndimage.binary_fill_holes(_largest_component(cells))
    cells &= defined[:-1, :-1] & defined[1:, :-1] & defined[:-1, 1:] & defined[1:, 1:]
    nx, nz = height.shape
    idx = np.arange(nx * nz).reshape(nx, nz)
    X, Z = np.meshgrid(xs, zs, indexing="ij")
    top = np.column_stack([X.ravel(), np.nan_to_num(height).ravel(), Z.ravel()])
    base_y = np.nanmax(height) + depth_mm
    base = top.copy()
    base[:, 1] = base_y
    i, k = np.nonzero(cells)
    a, b, c, d = idx[i, k], idx[i + 1, k], idx[i + 1, k + 1], idx[i, k + 1]
    # Top surface faces distal (-y): with x volar, z radial this winding points to -y.
    top_faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    n = nx * nz
    base_faces = top_faces[:, ::-1] + n
    # Boundary edges of the top surface (used once) get a wall down to the base.
    edges = np.concatenate([top_faces[:, [0, 1]], top_faces[:, [1, 2]], top_faces[:, [2, 0]]])
    key = np.sort(edges, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    boundary = edges[counts[inverse.ravel()] == 1]
    u, v = boundary[:, 0], boundary[:, 1]
    walls = np.concatenate([np.column_stack([v, u, u + n]), np.column_stack([v, u + n, v + n])])
    mesh = trimesh.Trimesh(np.vstack([top, base]), np.concatenate([top_faces, base_faces, walls]), process=True)
    mesh.remove_unreferenced_vertices()
    if mesh.volume < 0:
        mesh.invert()
    if not mesh.is_watertight:
        raise BuildError("the rebuilt distal radius cap is not watertight")
    return mesh


def build_radius_cap(
    row_meshes: Sequence[trimesh.Trimesh],
    radius_mesh: trimesh.Trimesh,
    *,
    joint_space_mm: float = 1.5,
    spacing_mm: float = 0.4,
    depth_mm: float = 4.0,
    sample_mm: float = 0.15,
    sweep_deg: tuple[float, float] = (0.0, 0.0),
    swept_sample_mm: float = 0.25,
    ulnar_border_z: float | None = None,
) -> tuple[trimesh.Trimesh, np.ndarray]:
    """The rebuilt distal radius articular solid and its articular (top) vertex mask.

    row_meshes: the scaphoid and lunate. sweep_deg: (flexion, deviation) half-ranges of the
    swept envelope, deg; (0, 0) moulds the fossae to the neutral row. sample_mm, swept_sample_mm:
    surface sampling of the row, mm (coarser when swept: every sample is repeated per pose). ulnar_border_z:
    the radius' ulnar border (z, mm, in the row's frame; None: no border): the fossae end there, as the
    radius they rebuild does (the envelope of the row reaches past it, over the ulnocarpal space, where the
    lunate's ulnar part rests on the TFCC, not on the radius). Returns (mesh, articular)
    where articular is a bool array over mesh vertices.
    """
    footprint = fossa_points(row_meshes, radius_mesh)
    row_points = []
    for mesh in row_meshes:
        # dense surface samples (not just vertices) so the envelope of balls is smooth
        if tuple(sweep_deg) == (0.0, 0.0):
            points = trimesh.sample.sample_surface_even(mesh, int(mesh.area / (sample_mm * sample_mm)), seed=0)[0]
            row_points.append(points)
            continue
        points, face = trimesh.sample.sample_surface_even(mesh, int(mesh.area / swept_sample_mm**2), seed=0)
        facing = mesh.face_normals[face, 1] > 0.0  # the proximally facing surface
        row_points.append(swept(points[facing], sphere_centre(fossa_points([mesh], radius_mesh)), *sweep_deg))
    row_points += [m.vertices for m in row_meshes]
    xs, zs, height = offset_heightfield(
        footprint, np.concatenate(row_points), joint_space_mm=joint_space_mm, spacing_mm=spacing_mm
    )
    if ulnar_border_z is not None:
        height[:, zs < ulnar_border_z] = np.nan
    mesh = extrude_heightfield(xs, zs, height, depth_mm=depth_mm)
    articular = mesh.vertices[:, 1] < mesh.vertices[:, 1].max() - 1e-6
    return mesh, articular
