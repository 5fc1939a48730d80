"""Rebuild the distal radius articular surface (scaphoid and lunate fossae).

The myo-sim radius is coarse (~10 mm edges) and sits 3.4–4.3 mm from the
proximal row. The articular surface is rebuilt as the offset envelope of the
proximal row's proximally facing surface at the radiocarpal joint space
(union of balls of radius `joint_space_mm` around the row's vertices, read
from the proximal side), sampled on a regular grid and extruded into a
watertight solid. Coordinates: an RCS-oriented frame (x volar, y proximal,
z radial), mm.
"""

from __future__ import annotations

import numpy as np
import trimesh
from scipy.spatial import cKDTree

from wrist_env.errors import BuildError


def fossa_points(row_meshes, radius_mesh, *, facing=0.3, reach_mm=8.0) -> np.ndarray:
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


def offset_heightfield(footprint, row_vertices, *, joint_space_mm=1.5, spacing_mm=0.5):
    """Height y(x, z) of the envelope at `joint_space_mm` proximal to the row.

    The envelope is taken over all `row_vertices` (so no vertex of the row
    comes closer than the joint space), on the x–z footprint of `footprint`
    points dilated by the joint space. Returns (xs, zs, height) with height of
    shape (len(xs), len(zs)), NaN off the footprint.
    """
    g = joint_space_mm
    lo = footprint[:, [0, 2]].min(axis=0) - g
    hi = footprint[:, [0, 2]].max(axis=0) + g
    xs = np.arange(lo[0], hi[0] + spacing_mm, spacing_mm)
    zs = np.arange(lo[1], hi[1] + spacing_mm, spacing_mm)
    X, Z = np.meshgrid(xs, zs, indexing="ij")
    grid = np.column_stack([X.ravel(), Z.ravel()])
    on_footprint = cKDTree(footprint[:, [0, 2]]).query(grid)[0] < g
    tree = cKDTree(row_vertices[:, [0, 2]])
    height = np.full(len(grid), np.nan)
    for i, neighbours in enumerate(tree.query_ball_point(grid, r=g * (1 - 1e-9))):
        if neighbours and on_footprint[i]:
            p = row_vertices[neighbours]
            d2 = ((p[:, [0, 2]] - grid[i]) ** 2).sum(axis=1)
            height[i] = np.max(p[:, 1] + np.sqrt(g * g - d2))
    return xs, zs, fill_creases(height.reshape(X.shape), sigma_cells=1.5)


def fill_creases(height, sigma_cells=1.5):
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


def extrude_heightfield(xs, zs, height, *, depth_mm=4.0) -> trimesh.Trimesh:
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


def build_radius_cap(row_meshes, radius_mesh, *, joint_space_mm=1.5, spacing_mm=0.4, depth_mm=4.0, sample_mm=0.15):
    """The rebuilt distal radius articular solid and its articular (top) vertex mask.

    Returns (mesh, articular) where articular is a bool array over mesh vertices.
    """
    footprint = fossa_points(row_meshes, radius_mesh)
    # dense surface samples (not just vertices) so the envelope of balls is smooth
    row_vertices = np.concatenate(
        [trimesh.sample.sample_surface_even(m, int(m.area / (sample_mm * sample_mm)), seed=0)[0] for m in row_meshes]
        + [m.vertices for m in row_meshes])
    xs, zs, height = offset_heightfield(footprint, row_vertices, joint_space_mm=joint_space_mm, spacing_mm=spacing_mm)
    mesh = extrude_heightfield(xs, zs, height, depth_mm=depth_mm)
    articular = mesh.vertices[:, 1] < mesh.vertices[:, 1].max() - 1e-6
    return mesh, articular
