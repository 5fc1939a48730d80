import numpy as np
import pytest
import trimesh

from wrist_env.builder.sdf import signed_distance_grid, trilinear


def test_sphere_grid_matches_the_closed_form_distance():
    R = 8.0
    mesh = trimesh.creation.icosphere(subdivisions=5, radius=R)
    grid = signed_distance_grid(mesh.vertices, mesh.faces, spacing_mm=0.5, margin_mm=3.0)
    rng = np.random.default_rng(0)
    p = rng.normal(size=(500, 3))
    p *= (rng.uniform(R - 2, R + 2, 500) / np.linalg.norm(p, axis=1))[:, None]
    value, grad = trilinear(grid, p)
    exact = np.linalg.norm(p, axis=1) - R
    assert np.abs(value - exact).max() < 0.03  # mm: tessellation + trilinear error
    unit = p / np.linalg.norm(p, axis=1)[:, None]
    cos = np.einsum("ij,ij->i", grad / np.linalg.norm(grad, axis=1)[:, None], unit)
    assert np.percentile(cos, 5) > 0.995


def test_inside_is_negative_and_band_is_clamped():
    mesh = trimesh.creation.box(extents=(10, 10, 10))
    grid = signed_distance_grid(mesh.vertices, mesh.faces, spacing_mm=0.5, margin_mm=2.0, band_mm=3.0)
    assert trilinear(grid, [[0, 0, 0]])[0][0] == pytest.approx(-3.0)
    assert trilinear(grid, [[6, 0, 0]])[0][0] == pytest.approx(1.0, abs=1e-5)
