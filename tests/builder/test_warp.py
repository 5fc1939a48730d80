import importlib.resources
import json

import igl
import numpy as np
import pytest
import trimesh

from wrist_env.builder.warp import Warp, apply_to_mesh, random_warp
from wrist_env.errors import InputError, MeshError


@pytest.fixture(scope="module")
def scaphoid():
    mesh = trimesh.load(importlib.resources.files("myo_sim") / "models/meshes/scaphoid.stl")
    mesh.apply_scale(1000.0)  # m -> mm
    return mesh


def grid(half_mm=40.0, n=21):
    axis = np.linspace(-half_mm, half_mm, n)
    return np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)


def test_random_warp_is_deterministic_for_a_seed():
    assert random_warp(7) == random_warp(7)
    assert random_warp(7) != random_warp(8)
    p = grid(n=5)
    np.testing.assert_array_equal(random_warp(7).apply(p), random_warp(7).apply(p))


def test_json_round_trip_is_exact():
    warp = random_warp(3, amplitude_mm=1.5, width_mm=12.0, centre=(1.0, -2.0, 3.0))
    back = Warp.from_dict(json.loads(json.dumps(warp.as_dict())))
    assert back == warp
    p = grid(n=5)
    np.testing.assert_array_equal(back.apply(p), warp.apply(p))


def test_apply_matches_the_closed_form_for_one_basis_function():
    warp = Warp(
        scale=1.1, centre=[1.0, 2.0, 3.0], rbf_centres=[[0.0, 0.0, 0.0]], rbf_weights=[[0.0, 0.0, 2.0]], width_mm=10.0
    )
    x = np.array([[10.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    bump = 2.0 * np.exp(-np.array([100.0, 0.0]) / 200.0)
    expected = warp.centre + 1.1 * (x - warp.centre + np.outer(bump, [0, 0, 1]))
    np.testing.assert_allclose(warp.apply(x), expected, rtol=0, atol=1e-12)


def test_jacobian_matches_central_differences():
    warp = random_warp(11, amplitude_mm=2.0, width_mm=10.0, extent_mm=20.0)
    x = np.random.default_rng(0).uniform(-25, 25, size=(50, 3))
    h = 1e-4
    numeric = np.stack([(warp.apply(x + h * e) - warp.apply(x - h * e)) / (2 * h) for e in np.eye(3)], axis=-1)
    np.testing.assert_allclose(warp.jacobian(x), numeric, atol=1e-7)


@pytest.mark.parametrize("seed", range(5))
def test_jacobian_determinant_is_positive_on_a_grid(seed):
    # Strongest warp the diffeomorphism bound allows at this width: sum |w| e^-1/2 / width = 0.97.
    amplitude = 0.97 * 10.0 / (6 * np.exp(-0.5))
    warp = random_warp(seed, amplitude_mm=amplitude, width_mm=10.0, extent_mm=20.0, scale_sd=0.05)
    assert warp.jacobian_det(grid(n=31)).min() > 0.0
    default = random_warp(seed)  # amplitude 1 mm, width 15 mm
    assert default.jacobian_det(grid()).min() > 0.5


def test_pure_scale_gives_the_cube_of_the_scale_in_volume(scaphoid):
    warp = Warp(
        scale=1.07, centre=[0.0, 0.0, 0.0], rbf_centres=np.zeros((0, 3)), rbf_weights=np.zeros((0, 3)), width_mm=15.0
    )
    warped = trimesh.Trimesh(apply_to_mesh(scaphoid.vertices, scaphoid.faces, warp), scaphoid.faces, process=False)
    assert warped.volume / scaphoid.volume == pytest.approx(1.07**3, rel=1e-9)


def test_volume_ratio_is_the_scale_cubed_on_average(scaphoid):
    # The RBF field changes local volume too (divergence ~ |w| / width), by up to ~9 % on a
    # 20 mm bone at 1 mm / 15 mm; it has no bias, so over many seeds the ratio is scale³.
    ratios = []
    for seed in range(20):
        warp = Warp.from_dict({**random_warp(seed, amplitude_mm=1.0).as_dict(), "scale": 1.05})
        warped = trimesh.Trimesh(apply_to_mesh(scaphoid.vertices, scaphoid.faces, warp), scaphoid.faces)
        ratios.append(warped.volume / scaphoid.volume / 1.05**3)
    assert np.mean(ratios) == pytest.approx(1.0, abs=0.02)
    assert np.abs(np.array(ratios) - 1.0).max() < 0.1


@pytest.mark.parametrize("seed", range(3))
def test_warped_volume_is_the_integrated_jacobian(scaphoid, seed):
    warp = Warp.from_dict({**random_warp(seed, amplitude_mm=1.0).as_dict(), "scale": 1.05})
    warped = trimesh.Trimesh(apply_to_mesh(scaphoid.vertices, scaphoid.faces, warp), scaphoid.faces, process=False)
    # Independent: the warped volume is the integral of det J over the template's interior (0.5 mm cells).
    lo, hi = scaphoid.bounds
    axes = [np.arange(lo[i], hi[i], 0.5) + 0.25 for i in range(3)]
    cells = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    winding = igl.fast_winding_number(
        np.asarray(scaphoid.vertices, dtype=np.float64), np.asarray(scaphoid.faces, dtype=np.int64), cells
    )
    integral = warp.jacobian_det(cells[winding > 0.5]).sum() * 0.5**3
    assert warped.volume == pytest.approx(integral, rel=0.01)


def test_mesh_keeps_winding_and_watertightness(scaphoid):
    warp = random_warp(5, amplitude_mm=2.0, width_mm=10.0, extent_mm=15.0)
    warped = trimesh.Trimesh(apply_to_mesh(scaphoid.vertices, scaphoid.faces, warp), scaphoid.faces, process=False)
    assert warped.is_watertight and warped.is_winding_consistent
    assert warped.volume > 0
    assert (np.einsum("ij,ij->i", warped.face_normals, scaphoid.face_normals) > 0.5).all()


def test_random_warp_scale_spread_follows_scale_sd():
    log_scale = np.log([random_warp(seed, scale_sd=0.05).scale for seed in range(400)])
    assert np.std(log_scale) == pytest.approx(0.05, rel=0.15)
    assert abs(np.mean(log_scale)) < 0.01


def test_bad_input_is_named():
    warp = random_warp(0)
    with pytest.raises(InputError, match=r"row 1 is \[nan, 0.0, 0.0\]"):
        warp.apply([[0.0, 0.0, 0.0], [np.nan, 0.0, 0.0]])
    with pytest.raises(InputError, match=r"shape \(n, 3\).*\(4, 2\)"):
        warp.apply(np.zeros((4, 2)))
    with pytest.raises(InputError, match="scale > 0.*-1.0"):
        Warp.from_dict({**warp.as_dict(), "scale": -1.0})
    with pytest.raises(InputError, match="diffeomorphism"):
        Warp.from_dict({**warp.as_dict(), "width_mm": 1.0})
    with pytest.raises(InputError, match="same shape.*\\(6, 3\\) and \\(5, 3\\)"):
        Warp.from_dict({**warp.as_dict(), "rbf_weights": warp.as_dict()["rbf_weights"][:5]})
    with pytest.raises(InputError, match="keys"):
        Warp.from_dict({"scale": 1.0})
    with pytest.raises(InputError, match="amplitude_mm >= 0.*-1"):
        random_warp(0, amplitude_mm=-1)


def test_bad_mesh_is_named():
    warp = random_warp(0)
    v = np.zeros((3, 3))
    with pytest.raises(MeshError, match=r"0\.\.2, but got indices 0\.\.3"):
        apply_to_mesh(v, [[0, 1, 3]], warp)
    with pytest.raises(MeshError, match="0 vertices and 0 faces"):
        apply_to_mesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=int), warp)
    with pytest.raises(MeshError, match=r"shape \(1, 4\)"):
        apply_to_mesh(v, [[0, 1, 2, 2]], warp)
    with pytest.raises(MeshError, match=r"`vertices` must be finite, but vertex 2 is \[0.0, inf, 0.0\]"):
        apply_to_mesh([[0, 0, 0], [1, 0, 0], [0, np.inf, 0]], [[0, 1, 2]], warp)
