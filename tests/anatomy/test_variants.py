"""Anatomy variants: the distal row and triquetrum as body parts, and the swept radius fossae."""

import igl
import numpy as np
import pytest

from wrist_env.anatomy.annotations import read_annotation_data, template_annotations
from wrist_env.anatomy.template import JOINT_SPACE_MM, load_template
from wrist_env.model import BODY_PARTS, BONES, PARTS

SWEEP = (20.0, 10.0)


@pytest.fixture(scope="module")
def default():
    return load_template()


@pytest.fixture(scope="module")
def wrist():
    return load_template(SWEEP, True)


def test_default_bodies_are_the_principal_bones(default):
    """Without the distal row each body is its principal bone, but the radial column, which is two
    bones in every variant (`model.BODY_PARTS`); the triquetrum is a body of its own in both."""
    for body in (b for b in BONES if b != "trapezium"):
        assert (default.bones[body].part == 0).all()
        np.testing.assert_array_equal(default.bones[body].vertices, default.parts[body].vertices)
    assert sorted(default.parts) == sorted(PARTS)


def test_distal_row_bodies_are_their_parts_in_order(wrist):
    for body in BONES:
        surface = wrist.bones[body]
        assert surface.part.max() == len(BODY_PARTS[body]) - 1
        for k, part in enumerate(BODY_PARTS[body]):
            np.testing.assert_array_equal(surface.vertices[surface.part == k], wrist.parts[part].vertices)
        assert surface.trimesh(solid_only=True).is_watertight or not surface.solid.any()  # closed parts, closed body


@pytest.mark.parametrize(
    "bone, partner, most_mm",
    [
        # a normal carpal joint space is at most ~2 mm (Gilula 1979); the distal row is seated at 1.5 mm
        ("scaphoid", "trapezoid", 2.0),  # the STT joint: the scaphoid's distal pole against the trapezoid
        ("scaphoid", "trapezium", 2.0),  # ... and the trapezium (2.38 mm as myo-sim assembles it)
        ("triquetrum", "hamate", 2.0),  # the triquetrohamate joint (0.60 mm as myo-sim assembles it)
        ("lunate", "triquetrum", 1.0),  # the lunotriquetral joint
    ],
)
def test_new_bones_articulate_where_anatomy_puts_them(wrist, bone, partner, most_mm):
    """Each new joint is open (no overlap) and within a joint space of its partner."""
    a, b = wrist.parts[bone], wrist.parts[partner]
    d2 = igl.point_mesh_squared_distance(a.vertices, b.vertices, b.faces)[0]
    inside = igl.winding_number(b.vertices, b.faces, a.vertices) > 0.5
    assert not inside.any()
    assert 0.2 < np.sqrt(d2.min()) < most_mm


def test_drc_inserts_on_the_triquetrum_with_the_distal_row(default, wrist):
    """The DRC's insertion is the triquetrum's dorsal tubercle (Mizuseki 1989), a body of its own; without the
    distal row (the triquetrum detached) the dorsal lunate."""
    spec = read_annotation_data()["ligaments"]["DRC"]["insertion"]
    assert spec["bone"] == "triquetrum" and spec["without_part"]["bone"] == "lunate"
    on_wrist = template_annotations(SWEEP, True).sites["DRC"][1]
    assert on_wrist.bone == "triquetrum" and on_wrist.mask.sum() > 8
    assert len(on_wrist.mask) == len(wrist.bones["triquetrum"].vertices)
    on_default = template_annotations().sites["DRC"][1]
    assert on_default.bone == "lunate" and on_default.mask.sum() > 8
    assert BODY_PARTS["lunate"] == ("lunate",)


def test_swept_fossae_keep_the_joint_space_and_open_only_where_the_row_turns(default, wrist):
    """The swept envelope lies proximal of the moulded one (never closer to the neutral row), keeps
    the joint space's minimum, and opens away from the neutral mould (it lets the row turn)."""
    moulded = default.bones["radius"].trimesh(solid_only=True)
    swept = wrist.bones["radius"].trimesh(solid_only=True)
    assert swept.is_watertight
    np.testing.assert_allclose(default.rcs_from_myosim, wrist.rcs_from_myosim)  # the RCS does not move
    for bone in ("scaphoid", "lunate"):
        v = default.parts[bone].vertices
        d_m = np.sqrt(igl.point_mesh_squared_distance(v, moulded.vertices, moulded.faces.astype(np.int64))[0])
        d_s = np.sqrt(igl.point_mesh_squared_distance(v, swept.vertices, swept.faces.astype(np.int64))[0])
        assert d_s.min() >= JOINT_SPACE_MM - 0.05
        near = d_m < JOINT_SPACE_MM + 0.5  # the articular part of the row
        assert np.all(d_s[near] >= d_m[near] - 0.05)
        assert np.median(d_s[near] - d_m[near]) > 0.05
