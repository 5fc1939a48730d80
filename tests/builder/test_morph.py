import importlib.resources

import numpy as np
import pytest
import trimesh

from wrist_env.builder.morph import morph, transfer_mask, transfer_points
from wrist_env.builder.warp import Warp, random_warp
from wrist_env.errors import InputError, MeshError


def carpal(bone: str) -> trimesh.Trimesh:
    mesh = trimesh.load(importlib.resources.files("myo_sim") / f"models/meshes/{bone}.stl")
    mesh.apply_scale(1000.0)  # m -> mm
    return mesh


def scaled_warp(seed, scale, **kwargs) -> Warp:
    return Warp.from_dict({**random_warp(seed, **kwargs).as_dict(), "scale": scale})


@pytest.fixture(scope="module", params=["scaphoid", "lunate"])
def warped_case(request):
    """Template bone, its warp (scale 1.05, 1 mm RBF amplitude), the warped copy and the morph onto it."""
    mesh = carpal(request.param)
    warp = scaled_warp(1, 1.05, amplitude_mm=1.0)
    target = warp.apply(mesh.vertices)
    return mesh, target, morph(mesh.vertices, mesh.faces, target, mesh.faces, seed=0)


def test_morph_recovers_the_warp(warped_case):
    mesh, target, result = warped_case
    vertex_error = np.linalg.norm(result.vertices - target, axis=1)
    similarity_only = np.linalg.norm(trimesh.transform_points(mesh.vertices, result.alignment) - target, axis=1)
    assert vertex_error.mean() < 0.5
    assert vertex_error.mean() < 0.6 * similarity_only.mean()  # the non-rigid stage does the work
    assert result.error_mean_mm < 0.05 and result.error_max_mm < 0.5
    # Surface error checked against trimesh's closest points (independent of libigl); 0.05 µm: with
    # trimesh 5.2 one vertex of 1,829 differed by 0.011 µm from libigl's exact point-triangle distance.
    _, distance, _ = trimesh.proximity.closest_point(
        trimesh.Trimesh(target, mesh.faces, process=False), result.vertices
    )
    np.testing.assert_allclose(result.surface_error_mm, distance, atol=5e-5)
    assert result.error_mean_mm == pytest.approx(distance.mean(), abs=1e-5)


def test_morph_recovers_a_warp_the_similarity_cannot():
    mesh = carpal("scaphoid")
    target = scaled_warp(1, 1.05, amplitude_mm=2.0, width_mm=10.0, extent_mm=20.0).apply(mesh.vertices)
    result = morph(mesh.vertices, mesh.faces, target, mesh.faces)
    similarity_only = np.linalg.norm(trimesh.transform_points(mesh.vertices, result.alignment) - target, axis=1)
    vertex_error = np.linalg.norm(result.vertices - target, axis=1)
    assert similarity_only.mean() > 0.8
    assert vertex_error.mean() < 0.5
    assert result.error_mean_mm < 0.05


def test_alignment_recovers_a_pure_similarity():
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=10.0)
    ellipsoid = sphere.vertices * [1.0, 0.8, 0.6]
    rotation = trimesh.transformations.rotation_matrix(0.1, [1, 2, 3])
    truth = trimesh.transformations.translation_matrix([0.5, -0.3, 0.2]) @ rotation @ np.diag([1.1, 1.1, 1.1, 1.0])
    target = trimesh.transform_points(ellipsoid, truth)
    result = morph(ellipsoid, sphere.faces, target, sphere.faces)
    scale = np.cbrt(np.linalg.det(result.alignment[:3, :3]))
    assert scale == pytest.approx(1.1, abs=1e-3)
    np.testing.assert_allclose(result.alignment[:3, 3], truth[:3, 3], atol=0.01)
    assert np.linalg.norm(result.vertices - target, axis=1).max() < 0.05


def test_transfer_mask_maps_patches_onto_the_warped_patches(warped_case):
    mesh, target, result = warped_case
    for centre in (0, 500, 1000):
        patch = np.linalg.norm(mesh.vertices - mesh.vertices[centre], axis=1) < 5.0
        # The target is the warped template in the same vertex order, so the truth is `patch` itself.
        moved = transfer_mask(result, patch, target)
        assert (moved & patch).sum() / (moved | patch).sum() > 0.9


def test_transfer_mask_onto_another_tessellation():
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=10.0)
    fine = trimesh.creation.icosphere(subdivisions=4, radius=10.5)
    result = morph(sphere.vertices, sphere.faces, fine.vertices, fine.faces)
    cap = sphere.vertices[:, 2] > 5.0
    moved = transfer_mask(result, cap, fine.vertices)
    # Truth: the same polar cap (z > 5 on radius 10, i.e. z > 5.25 on radius 10.5), up to one ring of edges.
    assert (moved & (fine.vertices[:, 2] > 5.25 + 1.5)).sum() == (fine.vertices[:, 2] > 5.25 + 1.5).sum()
    assert not (moved & (fine.vertices[:, 2] < 5.25 - 1.5)).any()


def test_transfer_points_follow_the_warp(warped_case):
    mesh, target, result = warped_case
    ids = np.array([0, 10, 100, 1000])
    points = transfer_points(result, ids)
    assert points.shape == (4, 3)
    np.testing.assert_array_equal(points, result.vertices[ids])
    assert np.linalg.norm(points - target[ids], axis=1).max() < 1.0


def test_morph_is_deterministic_and_equality_ignores_time():
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=10.0)
    ellipsoid = sphere.vertices * [1.0, 0.8, 0.6]
    target = scaled_warp(2, 1.02, amplitude_mm=0.5, width_mm=8.0, extent_mm=10.0).apply(ellipsoid)
    a = morph(ellipsoid, sphere.faces, target, sphere.faces, seed=4)
    b = morph(ellipsoid, sphere.faces, target, sphere.faces, seed=4)
    assert a == b
    assert a.seconds > 0


def test_bad_meshes_are_named():
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=10.0)
    v, f = np.array(sphere.vertices), np.array(sphere.faces)
    nan = v.copy()
    nan[7, 1] = np.nan
    with pytest.raises(MeshError, match=r"`target_vertices` must be finite, but vertex 7 is \[.*nan"):
        morph(v, f, nan, f)
    with pytest.raises(MeshError, match="template mesh must have vertices and faces, but got 0 vertices"):
        morph(np.zeros((0, 3)), np.zeros((0, 3), dtype=int), v, f)
    with pytest.raises(MeshError, match=r"`template_vertices` must have shape \(n, 3\), but got shape \(162, 2\)"):
        morph(v[:, :2], f, v, f)
    with pytest.raises(MeshError, match=r"`target_faces` must index vertices 0\.\.99, but got indices 0\.\.161"):
        morph(v, f, v[:100], f)
    with pytest.raises(MeshError, match=r"in mm.*0\.001"):
        morph(v, f, v / 1000.0, f)  # target in metres


def test_bad_annotations_are_named():
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=10.0)
    result = morph(sphere.vertices, sphere.faces, sphere.vertices, sphere.faces)
    with pytest.raises(InputError, match=r"bool of shape \(162,\), but got bool of shape \(10,\)"):
        transfer_mask(result, np.ones(10, dtype=bool), sphere.vertices)
    with pytest.raises(InputError, match=r"bool of shape \(162,\), but got int64"):
        transfer_mask(result, np.ones(162, dtype=np.int64), sphere.vertices)
    with pytest.raises(InputError, match="non-finite"):
        transfer_mask(result, np.ones(162, dtype=bool), np.full((3, 3), np.nan))
    with pytest.raises(InputError, match=r"0\.\.161, but got 0\.\.162"):
        transfer_points(result, [0, 162])
    with pytest.raises(InputError, match="integers"):
        transfer_points(result, [0.5])
