"""The built participants meet the foundation's acceptance criteria."""

import numpy as np
import pytest

from wrist_env.build.sdf import DistanceGrid, trilinear
from wrist_env.design import LIGAMENTS
from wrist_env.model import BONES, PAIR_BONES, PAIRS, Model

PARTICIPANTS = ("P1", "P2", "P3")


@pytest.mark.parametrize("name", PARTICIPANTS)
def test_fibre_counts_match_table_2(built, name):
    model = built(name)
    counts = np.bincount(model.fibre_ligament, minlength=len(LIGAMENTS))
    for k, lig in enumerate(LIGAMENTS):
        assert counts[k] == lig.fibres, lig.name
    assert model.report["fibres"] == {l.name: l.fibres for l in LIGAMENTS if l.fibres} | {"RSC": len(model.membrane_connectors)}


@pytest.mark.parametrize("name", PARTICIPANTS)
def test_joint_spaces_are_physiological(built, name):
    spaces = built(name).report["joint_space_mm"]
    assert set(spaces) == set(PAIRS)
    for art, gap in spaces.items():
        assert 0.5 <= gap <= 2.5, (art, gap)


@pytest.mark.parametrize("name", PARTICIPANTS)
def test_no_cartilage_overclosure_remains_in_the_neutral_pose(built, name):
    """Checked on the final model: every contact sample lies outside the opposing grid surface."""
    model = built(name)
    for p, pair in enumerate(PAIRS):
        grid_bone = BONES[PAIR_BONES[p][1]]
        i = BONES.index(grid_bone)
        grid = DistanceGrid(model.grid_origin[i], float(model.grid_spacing[i]), model.grid(grid_bone))
        pts = model.sample_points[model.sample_offsets[p]:model.sample_offsets[p + 1]]
        distance, _ = trilinear(grid, pts)
        assert distance.min() > -0.05, (pair, distance.min())  # mm: grid interpolation tolerance
        assert model.report["overclosure_mm"][pair] <= 1e-3


@pytest.mark.parametrize("name", PARTICIPANTS)
def test_cartilage_is_physiological_and_law_fits(built, name):
    report = built(name).report
    for art, t in report["cartilage_thickness_mm"].items():
        assert 0.0 < t["min"] <= t["mean"] <= t["max"] <= 1.1 + 1e-9, art
    radius_side = report["cartilage"]["articulations"]["radius-scaphoid"]["thickness_mm"]["radius"]
    assert 0.5 <= radius_side["mean"] <= 0.9  # distal radius cartilage ~0.6–0.8 mm (19 wrists)
    assert report["contact_law_r2"] >= 0.99


def test_morph_error_is_reported_and_small(built):
    errors = built("P1").report["morph_error_mm"]
    assert set(errors) == set(BONES)
    for bone, e in errors.items():
        assert 0 <= e["mean"] <= e["max"] < 1.0, bone


def test_participants_differ_by_their_warp(built):
    a, b = built("P1"), built("P2")
    assert a.source_hash != b.source_hash
    assert b.mass[BONES.index("scaphoid")] > a.mass[BONES.index("scaphoid")]  # P2 (male) scaled up, P1 down


def test_model_round_trips_through_npz_and_json(built, tmp_path):
    model = built("P1")
    model.save(tmp_path / "m")
    again = Model.load(tmp_path / "m")
    assert again.report == model.report and again.name == model.name
    for field in ("vertices", "grid_values", "sample_points", "fibre_origin", "membrane_connectors", "contact_law"):
        np.testing.assert_array_equal(getattr(again, field), getattr(model, field))
    assert not again.vertices.flags.writeable
    assert (tmp_path / "m.json").read_text().startswith("{")  # JSON + npz, no pickle
    with np.load(tmp_path / "m.npz", allow_pickle=False) as data:
        assert "grid_values" in data.files


def test_load_model_uses_the_cache(built, model_cache):
    from wrist_env.participants.registry import load_model

    built("P1")
    files = sorted(p.name for p in model_cache.iterdir())
    assert any(f.startswith("P1-") and f.endswith(".npz") for f in files)
    again = load_model("P1")
    assert again.report["build_seconds"] == built("P1").report["build_seconds"]  # read back, not rebuilt


@pytest.mark.parametrize("name", PARTICIPANTS)
def test_tracked_centroid_is_the_principal_bones_and_parts_recover_it(built, name):
    """With single-bone bodies (the default anatomy) the tracked centroid is the centre of mass, and
    `part_mesh` returns each body's own mesh; the six other parts are absent."""
    model = built(name)
    np.testing.assert_allclose(model.centroid, model.com, atol=1e-9)
    assert (model.vertex_part == 0).all()
    for bone in BONES:
        v, f = model.part_mesh(bone)
        bv, bf = model.bone_mesh(bone)
        np.testing.assert_array_equal(v, bv)
        np.testing.assert_array_equal(f, bf)
    v, f = model.part_mesh("hamate")
    assert len(v) == 0 and len(f) == 0
