import importlib.resources
import json

import igl
import numpy as np
import pytest
import trimesh

from wrist_env.builder.cartilage import (
    build_cartilage,
    cartilage_layer,
    extrude_wedges,
    remove_overclosure,
    thickness_fields,
    wedge_quality,
)
from wrist_env.builder.surface import closed_faces, displaced_vertices, gap_to, grnn_smooth
from wrist_env.errors import BuildError, InputError, MeshError

R = 10.0


def sphere(radius=R, centre=(0.0, 0.0, 0.0), inside_out=False):
    """Icosphere (subdivisions 4, ~0.66 mm edges at R = 10) as (vertices, faces)."""
    m = trimesh.creation.icosphere(subdivisions=4, radius=radius)
    faces = m.faces[:, ::-1] if inside_out else m.faces
    return m.vertices + np.asarray(centre), np.ascontiguousarray(faces, dtype=np.int64)


def plane_points(spacing=0.5, half=10.0, jitter=0.0, seed=0):
    g = np.arange(-half, half + 1e-9, spacing)
    x, y = np.meshgrid(g, g, indexing="ij")
    p = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    p[:, :2] += np.random.default_rng(seed).uniform(-jitter, jitter, (len(p), 2))
    return p


# --- GRNN -------------------------------------------------------------------


def test_grnn_returns_a_constant_field_exactly():
    rng = np.random.default_rng(1)
    points = rng.uniform(-5, 5, (400, 3))
    query = rng.uniform(-6, 6, (300, 3))
    out = grnn_smooth(points, np.full(400, 0.83), 1.0, query)
    assert np.abs(out - 0.83).max() < 1e-12


def test_grnn_reduces_the_variance_of_a_noisy_field():
    p = plane_points()
    noisy = 0.7 + np.random.default_rng(2).normal(0, 0.1, len(p))
    smooth = grnn_smooth(p, noisy, 1.0)
    interior = np.abs(p[:, :2]).max(axis=1) < 7
    assert smooth[interior].var() < 0.05 * noisy[interior].var()
    assert abs(smooth[interior].mean() - 0.7) < 0.01


def test_grnn_reproduces_a_linear_field_in_the_interior():
    p = plane_points(jitter=0.2)
    field = 0.3 * p[:, 0] - 0.2 * p[:, 1] + 1.0
    out = grnn_smooth(p, field, 1.0)
    interior = np.abs(p[:, :2]).max(axis=1) < 10 - 3.0
    assert np.abs(out[interior] - field[interior]).max() < 0.03  # mm; slope 0.36, σ 1 mm
    edge = np.abs(p[:, :2]).max(axis=1) > 9.8
    assert np.abs(out[edge] - field[edge]).max() > 0.1  # Nadaraya–Watson is biased at a border


def test_grnn_query_far_from_every_point_takes_the_nearest_value():
    out = grnn_smooth([[0, 0, 0], [1, 0, 0]], [2.0, 5.0], 0.1, query=[[10, 0, 0]])
    assert out[0] == 5.0


def test_grnn_smooths_vector_values_per_component():
    p = plane_points(spacing=1.0, half=4.0)
    values = np.column_stack([np.full(len(p), 1.5), np.full(len(p), -2.0)])
    assert np.allclose(grnn_smooth(p, values, 1.0), values, atol=1e-12)


# --- thickness ---------------------------------------------------------------


def test_gap_between_concentric_spheres_is_the_radial_gap():
    va, fa = sphere()
    vb, fb = sphere(11.5, inside_out=True)
    d, closest, face = gap_to(va, np.ones(len(va), bool), vb, fb, np.ones(len(vb), bool))
    assert d.shape == (len(va),) and closest.shape == (len(va), 3) and face.max() < len(fb)
    assert np.abs(d - 1.5).max() < 0.02  # facet sagitta of the outer sphere ~0.01 mm
    assert np.allclose(np.linalg.norm(closest - va, axis=1), d)


def test_thickness_is_the_share_of_a_closed_form_gap():
    c = np.array([0.0, 0.0, 0.3])
    va, fa = sphere()
    vb, fb = sphere(11.8, centre=c, inside_out=True)  # gap 1.5 mm (top) to 2.1 mm (bottom)
    arts = {("a", "b"): (np.ones(len(va), bool), np.ones(len(vb), bool))}
    t = thickness_fields({"a": va, "b": vb}, {"a": fa, "b": fb}, arts, share=0.5)
    gap_a = 11.8 - np.linalg.norm(va - c, axis=1)
    gap_b = np.linalg.norm(vb, axis=1) - R
    assert np.ptp(gap_a) > 0.55
    assert np.abs(t["a"] - 0.5 * gap_a).max() < 0.02
    assert np.abs(t["b"] - 0.5 * gap_b).max() < 0.02


def test_a_bone_in_two_articulations_takes_the_larger_thickness():
    va, fa = sphere()
    v1, f1 = sphere(11.0, inside_out=True)
    v2, f2 = sphere(11.6, inside_out=True)
    full = np.ones(len(va), bool)
    arts = {("a", "near"): (full, full), ("a", "far"): (full, full)}
    t = thickness_fields({"a": va, "near": v1, "far": v2}, {"a": fa, "near": f1, "far": f2}, arts)
    assert np.abs(t["a"] - 0.8).max() < 0.02
    assert np.abs(t["near"] - 0.5).max() < 0.02


def test_thickness_is_clipped_to_its_bounds_and_zero_off_coverage():
    va, fa = sphere()
    vb, fb = sphere(14.0, inside_out=True)  # share of the gap: 2 mm
    upper = va[:, 2] > 0
    arts = {("a", "b"): (upper, np.ones(len(vb), bool))}
    t = thickness_fields({"a": va, "b": vb}, {"a": fa, "b": fb}, arts)
    assert np.all(t["a"][upper] == 1.1) and np.all(t["a"][~upper] == 0.0)
    t = thickness_fields({"a": va, "b": vb}, {"a": fa, "b": fb}, arts, max_thickness_mm=0.9)
    assert t["a"].max() == 0.9
    vb, fb = sphere(10.1, inside_out=True)  # share of the gap: 0.05 mm
    t = thickness_fields({"a": va, "b": vb}, {"a": fa, "b": fb}, arts, min_thickness_mm=0.1)
    assert np.all(t["a"][upper] == 0.1)


# --- displacement and wedges -----------------------------------------------


def test_displacement_moves_covered_vertices_outward_by_their_thickness():
    v, f = sphere()
    t = np.where(v[:, 2] > 0, 0.5, 0.0)
    d = displaced_vertices(v, f, t)
    assert np.allclose(np.linalg.norm(d - v, axis=1)[t > 0], 0.5)
    radius = np.linalg.norm(d, axis=1)
    assert np.abs(radius[t > 0] - (R + 0.5)).max() < 2e-3  # directions tilt slightly at the patch border
    assert np.array_equal(d[t == 0], v[t == 0])


def test_wedge_volume_of_a_uniform_layer_is_the_shell_volume():
    v, f = sphere()
    t = np.full(len(v), 0.5)
    nodes, wedges = extrude_wedges(v, f, t)
    assert nodes.shape == (2 * len(v), 3) and wedges.shape == (len(f), 6) and wedges.dtype == np.int64
    lift = np.linalg.norm(nodes[wedges[:, 3:]] - nodes[wedges[:, :3]], axis=2)
    assert np.allclose(lift, 0.5)
    q = wedge_quality(nodes, wedges)
    shell = 4 / 3 * np.pi * ((R + 0.5) ** 3 - R**3)
    assert q["volume_mm3"] == pytest.approx(shell, rel=0.01)
    assert q["elements"] == len(f) and q["inverted"] == 0
    assert q["min_angle_deg"]["min"] > 20
    assert 1.0 < q["aspect_ratio"]["min"] <= q["aspect_ratio"]["median"] <= q["aspect_ratio"]["max"] < 2.0


def test_quality_of_one_right_prism_and_of_its_inverted_copy():
    nodes = np.array([[0, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, 0.5], [2, 0, 0.5], [0, 1, 0.5]], float)
    q = wedge_quality(nodes, [[0, 1, 2, 3, 4, 5]])
    assert q["volume_mm3"] == pytest.approx(0.5)  # triangle area 1 mm² × 0.5 mm
    assert q["aspect_ratio"]["max"] == pytest.approx(np.sqrt(5) / 0.5, abs=1e-4)
    assert q["min_angle_deg"]["min"] == pytest.approx(np.degrees(np.arctan(0.5)), abs=1e-4)
    assert q["inverted"] == 0
    flipped = wedge_quality(nodes, [[3, 4, 5, 0, 1, 2]])
    assert flipped["inverted"] == 1 and flipped["volume_mm3"] == pytest.approx(-0.5)


def test_wedges_cover_only_triangles_with_cartilage_on_all_three_vertices():
    v, f = sphere()
    t = np.where(v[:, 2] > 5, 0.4, 0.0)
    layer = cartilage_layer("a", v, f, t)
    full = (t[f] > 0).all(axis=1)
    assert len(layer.wedges) == full.sum()
    assert np.array_equal(layer.nodes[: len(layer.vertex_ids)], v[layer.vertex_ids])
    assert set(layer.vertex_ids) == set(np.unique(f[full]))


# --- overclosure -------------------------------------------------------------


def two_spheres(gap=1.0, reach=4.0):
    va, fa = sphere()
    u = va[0] / np.linalg.norm(va[0])  # a vertex on the line of centres (the icosphere is point-symmetric)
    vb, fb = sphere(centre=(2 * R + gap) * u)
    cover_a = np.linalg.norm(va - (2 * R + gap) * u, axis=1) - R < reach
    cover_b = np.linalg.norm(vb, axis=1) - R < reach
    tip_b = int(np.argmin(np.linalg.norm(vb - (R + gap) * u, axis=1)))
    return {"a": va, "b": vb}, {"a": fa, "b": fb}, {("a", "b"): (cover_a, cover_b)}, tip_b


def test_overclosure_removal_separates_two_overlapping_layers():
    v, f, arts, tip_b = two_spheres(gap=1.0)
    ((cover_a, cover_b),) = arts.values()
    t0 = {"a": np.where(cover_a, 0.8, 0.0), "b": np.where(cover_b, 0.8, 0.0)}
    t, report = remove_overclosure(v, f, t0, arts)
    r = report["a-b"]
    assert r["overclosure_before_mm"] == pytest.approx(0.6, abs=0.01)
    assert r["overclosure_after_mm"] <= 1e-3 and r["vertices_changed"] > 0
    assert min(x.min() for x in t.values()) >= 0
    assert 0.95 <= t["a"][0] + t["b"][tip_b] <= 1.0 + 1e-3  # the layers fill the 1 mm gap on the axis
    far = np.linalg.norm(v["a"] - v["a"][0], axis=1) > 4.0
    assert np.all(t["a"][far & cover_a] == 0.8)
    # independent check (trimesh's ray/winding signed distance, positive inside)
    da, db = (displaced_vertices(v[x], f[x], t[x]) for x in "ab")
    inside = trimesh.proximity.signed_distance(trimesh.Trimesh(db, f["b"]), da[t["a"] > 0])
    assert inside.max() <= 1e-3


def test_layers_that_fit_are_left_alone():
    v, f, arts, _ = two_spheres(gap=2.0)
    ((cover_a, cover_b),) = arts.values()
    t0 = {"a": np.where(cover_a, 0.8, 0.0), "b": np.where(cover_b, 0.8, 0.0)}
    t, report = remove_overclosure(v, f, t0, arts)
    assert report["a-b"]["vertices_changed"] == 0 and report["a-b"]["overclosure_before_mm"] == 0
    assert all(np.array_equal(t[x], t0[x]) for x in "ab")


def test_overclosure_ignores_an_open_part_of_the_other_bone():
    v, f, arts, _ = two_spheres(gap=2.0)
    shaft = trimesh.creation.cylinder(radius=3, height=20).subdivide()
    keep = shaft.face_normals[:, 2] < 0.9  # drop the top cap: an open tube through the other sphere
    tube = shaft.faces[keep] + len(v["b"])
    v = {"a": v["a"], "b": np.vstack([v["b"], shaft.vertices + v["b"].mean(axis=0)])}
    f = {"a": f["a"], "b": np.vstack([f["b"], tube])}
    cover_a, cover_b = arts[("a", "b")]
    arts = {("a", "b"): (cover_a, np.concatenate([cover_b, np.zeros(len(shaft.vertices), bool)]))}
    assert len(closed_faces(f["b"])) == len(f["b"]) - len(tube)
    t0 = {"a": np.where(cover_a, 0.8, 0.0), "b": np.where(arts[("a", "b")][1], 0.8, 0.0)}
    _, report = remove_overclosure(v, f, t0, arts)
    assert report["a-b"]["vertices_changed"] == 0


# --- the whole step ---------------------------------------------------------


def test_build_cartilage_on_concentric_spheres_reports_plain_numbers():
    va, fa = sphere()
    vb, fb = sphere(11.5, inside_out=True)
    arts = {("a", "b"): (np.ones(len(va), bool), np.ones(len(vb), bool))}
    t, report = build_cartilage({"a": va, "b": vb}, {"a": fa, "b": fb}, arts)
    json.dumps(report, allow_nan=False)
    r = report["cartilage"]["articulations"]["a-b"]
    assert r["joint_space_mm"] == pytest.approx(1.5, abs=0.02)
    assert r["overclosure_after_mm"] <= 1e-3
    assert r["thickness_mm"]["a"]["mean"] == pytest.approx(0.75, abs=0.02)
    q = report["cartilage"]["quality"]["a"]
    assert q["inverted"] == 0
    assert q["volume_mm3"] == pytest.approx(4 / 3 * np.pi * ((R + 0.75) ** 3 - R**3), rel=0.02)
    assert set(t) == {"a", "b"}


def myo_sim_pair():
    root = importlib.resources.files("myo_sim") / "models/meshes"
    meshes = {b: trimesh.load(str(root / f"{b}.stl")) for b in ("scaphoid", "lunate")}
    v = {b: np.asarray(m.vertices) * 1000.0 for b, m in meshes.items()}
    v["scaphoid"] = v["scaphoid"] + np.array([12.345, -4.464, -1.254])  # assembly offset from the lunate
    f = {b: np.asarray(m.faces, dtype=np.int64) for b, m in meshes.items()}

    def near(a, b):
        return np.sqrt(igl.point_mesh_squared_distance(v[a], v[b], f[b])[0]) < 2.5

    return v, f, {("scaphoid", "lunate"): (near("scaphoid", "lunate"), near("lunate", "scaphoid"))}


def test_scapholunate_cartilage_on_the_myo_sim_bones():
    v, f, arts = myo_sim_pair()
    t, report = build_cartilage(v, f, arts)
    r = report["cartilage"]["articulations"]["scaphoid-lunate"]
    assert 0.8 < r["joint_space_mm"] < 2.5
    assert r["overclosure_before_mm"] > 0.05 and r["overclosure_after_mm"] <= 1e-3
    for bone, mask in zip(("scaphoid", "lunate"), arts[("scaphoid", "lunate")]):
        assert 0.1 <= t[bone][mask].min() and t[bone].max() <= 1.1
        assert np.all(t[bone][~mask] == 0)
    da, db = (displaced_vertices(v[x], f[x], t[x]) for x in ("scaphoid", "lunate"))
    inside = trimesh.proximity.signed_distance(trimesh.Trimesh(db, f["lunate"]), da[t["scaphoid"] > 0])
    assert inside.max() <= 2e-3


# --- bad input ----------------------------------------------------------------


def test_bad_input_gets_a_clear_error():
    va, fa = sphere()
    vb, fb = sphere(11.5, inside_out=True)
    full = np.ones(len(va), bool)
    with pytest.raises(MeshError, match="finite"):
        bad = va.copy()
        bad[3] = np.nan
        thickness_fields({"a": bad, "b": vb}, {"a": fa, "b": fb}, {("a", "b"): (full, full)})
    with pytest.raises(InputError, match="bool"):
        thickness_fields({"a": va, "b": vb}, {"a": fa, "b": fb}, {("a", "b"): (full.astype(int), full)})
    with pytest.raises(InputError, match="lack"):
        thickness_fields({"a": va}, {"a": fa}, {("a", "b"): (full, full)})
    with pytest.raises(BuildError, match="covers none"):
        thickness_fields({"a": va, "b": vb}, {"a": fa, "b": fb}, {("a", "b"): (full, np.zeros(len(vb), bool))})
    with pytest.raises(InputError, match="bandwidth_mm > 0"):
        grnn_smooth(va, np.ones(len(va)), 0.0)
    with pytest.raises(InputError, match="share"):
        thickness_fields({"a": va, "b": vb}, {"a": fa, "b": fb}, {("a", "b"): (full, full)}, share=1.5)
    with pytest.raises(InputError, match=">= 0"):
        displaced_vertices(va, fa, -np.ones(len(va)))
