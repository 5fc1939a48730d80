"""The fossa morphometry probe's measures (experiments/research/fossa_morphometry.py) on surfaces whose answers
are known in closed form: a sphere cap's area and radius, a tilted plane's slope, two spherical cups' ridge."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest
import trimesh

import wrist_env

ROOT = Path(wrist_env.__file__).resolve().parent.parent
_spec = importlib.util.spec_from_file_location(
    "fossa_morphometry", ROOT / "experiments" / "research" / "fossa_morphometry.py"
)
fm = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(fm)


def cup(R: float, centre=(0.0, -10.0, 0.0), half_width: float = 6.0, step: float = 0.1) -> np.ndarray:
    """A fossa-like cup: the proximal (+y) side of a sphere of radius R, sampled on an x–z grid, (n, 3)."""
    g = np.arange(-half_width, half_width + step / 2, step)
    X, Z = np.meshgrid(g + centre[0], g + centre[2], indexing="ij")
    d2 = (X - centre[0]) ** 2 + (Z - centre[2]) ** 2
    keep = d2 < R**2
    return np.column_stack([X[keep], centre[1] + np.sqrt(R**2 - d2[keep]), Z[keep]])


def test_vertex_areas_sum_to_the_mesh_area_and_a_sphere_cap_has_its_closed_form_area():
    R, cos_t = 10.0, 0.6
    sphere = trimesh.creation.icosphere(subdivisions=5, radius=R)
    v, f = sphere.vertices, sphere.faces
    assert fm.vertex_areas(v, f).sum() == pytest.approx(sphere.area, rel=1e-12)
    cap = v[:, 1] > R * cos_t
    assert fm.patch_area(v, f, cap) == pytest.approx(2 * np.pi * R**2 * (1 - cos_t), rel=0.01)


def test_vertex_normals_point_out_of_a_sphere():
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=5.0)
    n = fm.vertex_normals(sphere.vertices, sphere.faces)
    radial = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1, keepdims=True)
    assert np.einsum("ij,ij->i", n, radial).min() > 0.999


def test_a_circle_and_a_sphere_fit_give_their_radius_on_a_short_arc():
    t = np.radians(np.linspace(-30, 30, 40))
    centre, R, rms = fm.fit_circle(np.column_stack([3 + 12 * np.cos(t), -2 + 12 * np.sin(t)]))
    assert R == pytest.approx(12.0, rel=1e-9) and centre == pytest.approx([3, -2]) and rms < 1e-9
    p = cup(9.0, half_width=4.0)
    centre, R, rms = fm.fit_sphere(p)
    assert R == pytest.approx(9.0, rel=1e-9) and centre == pytest.approx([0, -10, 0], abs=1e-8)


def test_a_sphere_caps_sections_through_its_centroid_have_its_radius():
    p = cup(11.0, centre=(1.0, -10.0, -2.0), half_width=5.0)
    radii = fm.section_radii(p, p.mean(axis=0))
    # a slab ±0.5 mm off the centre plane holds circles down to sqrt(R² − 0.25): at most 0.011 mm smaller
    assert radii["sagittal"] == pytest.approx(11.0, abs=0.012)
    assert radii["coronal"] == pytest.approx(11.0, abs=0.012)
    thin = fm.section_radii(p, p.mean(axis=0), slab_mm=0.01)
    assert thin["sagittal"] == pytest.approx(11.0, rel=1e-6) and thin["coronal"] == pytest.approx(11.0, rel=1e-6)


def test_an_ellipsoidal_cup_gives_its_two_principal_radii_of_curvature_at_the_floor():
    # y = c − x²/(2 Rx) − z²/(2 Rz): radii of curvature Rx (sagittal) and Rz (coronal) at the floor
    g = np.arange(-1.5, 1.55, 0.05)
    X, Z = np.meshgrid(g, g, indexing="ij")
    p = np.column_stack([X.ravel(), (-(X**2) / (2 * 8.0) - Z**2 / (2 * 14.0)).ravel(), Z.ravel()])
    radii = fm.section_radii(p, np.zeros(3), slab_mm=0.01)
    assert radii["sagittal"] == pytest.approx(8.0, rel=0.02)
    assert radii["coronal"] == pytest.approx(14.0, rel=0.02)


@pytest.mark.parametrize("deg", [-8.0, 0.0, 11.0, 23.0])
def test_a_tilted_plane_gives_the_slope_it_was_tilted_by(deg):
    g = np.arange(-10, 10.01, 0.5)
    X, Z = np.meshgrid(g, g, indexing="ij")
    volar = np.column_stack([X.ravel(), np.tan(np.radians(deg)) * X.ravel(), Z.ravel()])
    assert fm.rim_slope(volar, 0) == pytest.approx(deg, abs=1e-9)  # volar rim proximal: + volar tilt
    assert fm.rim_slope(volar, 0, through=np.zeros(3)) == pytest.approx(deg, abs=1e-9)
    radial = np.column_stack([X.ravel(), -np.tan(np.radians(deg)) * Z.ravel(), Z.ravel()])
    assert -fm.rim_slope(radial, 2) == pytest.approx(deg, abs=1e-9)  # radial rim distal: + inclination


def test_the_rims_of_a_cup_are_level():
    assert fm.rim_slope(cup(10.0), 0, through=np.array([0.0, 0.0, 0.0])) == pytest.approx(0.0, abs=1e-9)


def test_radial_inclination_of_a_styloid_tip_and_ulnar_corner():
    tip, corner = np.array([0.0, -8.0, 16.0]), np.array([-6.0, 2.0, -8.0])
    assert fm.inclination(tip, corner) == pytest.approx(np.degrees(np.arctan2(10.0, 24.0)))
    assert fm.inclination(corner * [1, 1, -1], tip * [1, 1, -1]) < 0  # tip proximal of the corner


def test_two_cups_ridge_stands_its_closed_form_height_between_their_floors():
    R, a = 10.0, 4.0
    g = np.arange(-5, 5.01, 0.05)
    X, Z = np.meshgrid(g, g, indexing="ij")
    x, z = X.ravel(), Z.ravel()
    cups = [np.sqrt(np.clip(R**2 - x**2 - (z - c) ** 2, 0, None)) for c in (a, -a)]
    p = np.column_stack([x, np.maximum(*cups), z])  # the envelope of two balls: a crest where they meet
    ridge = fm.ridge_profile(p, z > 0, z < 0, [0.0], slab_mm=0.03, bin_mm=0.05)
    (r,) = ridge
    height = R - np.sqrt(R**2 - a**2)
    assert r["ridge_z"] == pytest.approx(0.0, abs=0.05)
    for key in ("above_scaphoid", "above_lunate", "above_chord"):
        assert r[key] == pytest.approx(height, abs=0.02)
    assert fm.ridge_profile(p, z > 0, np.zeros(len(p), bool), [0.0]) == []  # one fossa only: no ridge


def test_a_single_cup_split_in_two_has_no_ridge():
    p = cup(10.0, centre=(0.0, 0.0, 0.0), half_width=5.0, step=0.05)
    (r,) = fm.ridge_profile(p, p[:, 2] > 0, p[:, 2] < 0, [0.0], slab_mm=0.03, bin_mm=0.05)
    assert r["above_chord"] == pytest.approx(0.0, abs=0.01)
