"""The template is real anatomy in the RCS: checked against anatomical facts."""

import igl
import numpy as np
import pytest
import trimesh

from wrist_env.anatomy.annotations import template_annotations
from wrist_env.anatomy.myosim import load_myosim_anatomy
from wrist_env.anatomy.template import JOINT_SPACE_MM, BoneSurface, carry_parts, closed, load_template
from wrist_env.model import SUPPLIED


@pytest.fixture(scope="module")
def template():
    return load_template()


def test_rcs_is_a_proper_rotation(template):
    R = template.rcs_from_myosim[:3, :3]
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0)


def test_scaphoid_lies_radial_to_the_lunate(template):
    assert template.bones["scaphoid"].vertices.mean(axis=0)[2] > template.bones["lunate"].vertices.mean(axis=0)[2] + 5


def test_radial_styloid_is_radial_and_distal(template):
    radius = load_myosim_anatomy().meshes["radius"].copy()
    radius.apply_transform(template.rcs_from_myosim)
    tip = radius.vertices[np.argmin(radius.vertices[:, 1])]
    assert tip[2] > 10.0  # radial of the articular centre by more than a fossa half-width
    assert tip[1] < -5.0  # distal of the articular centre


def test_ulna_is_ulnar_and_carpus_distal(template):
    assert template.bones["ulna"].vertices.mean(axis=0)[2] < -10
    for bone in ("scaphoid", "lunate", "capitate"):
        assert template.bones[bone].vertices.mean(axis=0)[1] < 0


def test_the_ulnas_cut_is_closed_into_a_solid_head(template):
    """The ulna (its distal 20 mm) is closed at the cut for its contact grid (the TFCC): watertight,
    outward, its volume that of a 20 mm piece of ulna (a 15-20 mm wide head: 2-6 cm³), and a closed
    bone comes back as it is; a cut cylinder gets the disc's area back (π r², within the polygon's)."""
    ulna = template.bones["ulna"]
    mesh = ulna.trimesh()
    assert ulna.solid.all() and mesh.is_watertight and mesh.is_winding_consistent
    assert 2000.0 < mesh.volume < 6000.0, mesh.volume
    assert closed(ulna) is ulna
    tube = trimesh.creation.cylinder(radius=5.0, height=10.0, sections=64)
    top = tube.triangles_center[:, 2] > 4.99
    cut = tube.submesh([np.flatnonzero(~top)], append=True)
    surface = BoneSurface("ulna", cut.vertices, cut.faces.astype(np.int64), np.zeros(len(cut.vertices), bool))
    capped = closed(surface).trimesh()
    assert capped.is_watertight and capped.volume > 0
    assert capped.area - cut.area == pytest.approx(tube.area - cut.area, rel=1e-9)


def test_scaphoid_is_flexed_with_its_distal_pole_volar(template):
    """In the neutral wrist the scaphoid lies flexed: its distal pole (tubercle) is volar of its proximal pole."""
    s = template.bones["scaphoid"].vertices
    distal, proximal = s[np.argmin(s[:, 1])], s[np.argmax(s[:, 1])]
    assert distal[0] - proximal[0] > 4.0


def test_rebuilt_fossae_are_fine_watertight_and_congruent(template):
    cap = template.bones["radius"].trimesh(solid_only=True)
    assert cap.is_watertight and cap.volume > 0
    radius = template.bones["radius"]
    ann = template_annotations()
    fossae = ann.coverage["radioscaphoid"][2] | ann.coverage["radiolunate"][2]
    edges = radius.trimesh().edges_unique
    edges = edges[fossae[edges].all(axis=1)]
    lengths = np.linalg.norm(radius.vertices[edges[:, 0]] - radius.vertices[edges[:, 1]], axis=1)
    assert np.percentile(lengths, 95) <= 1.0 and np.median(lengths) < 0.6  # ≤ 1 mm resolution
    # joint space: proximal-row vertices facing the fossae sit one joint space away

    for art in ("radioscaphoid", "radiolunate"):
        _, bone, _, mask = ann.coverage[art]
        d2 = igl.point_mesh_squared_distance(
            template.bones[bone].vertices[mask], cap.vertices, cap.faces.astype(np.int64)
        )[0]
        gap = np.sqrt(d2)
        assert np.median(gap) == pytest.approx(JOINT_SPACE_MM, abs=0.15)
        assert gap.min() > 1.0


def test_carpal_meshes_are_watertight_and_fine(template):
    for bone in ("scaphoid", "lunate", "capitate"):
        mesh = template.bones[bone].trimesh()
        assert mesh.is_watertight
        assert 0.4 < mesh.edges_unique_length.mean() < 1.0


@pytest.mark.parametrize("sweep", [(float("nan"), float("nan")), (20.0, float("inf")), (-1.0, 10.0), (120.0, 10.0)])
def test_a_template_is_not_swept_through_angles_out_of_range(sweep):
    """Issue 53: `--fossa-sweep nan nan` swept (and cached) a template from NaN angles."""
    from wrist_env.errors import InputError

    with pytest.raises(InputError, match=r"fossa_sweep_deg \w+ must be a finite number in \[0, 90\]"):
        load_template(sweep, True)


def test_the_rebuilt_fossae_end_at_the_radius_ulnar_border():
    """The rebuilt articular solid reaches the ulnar border of myo-sim's radius (the corner rule's, on the
    template's distal radius kept beside it) and stops there, within a grid spacing (0.4 mm): the lunate's
    ulnar part lies over the ulnocarpal space, on the TFCC, not on a fossa the radius lacks (issue 54)."""
    from wrist_env.anatomy.ulnar_variance import radius_bone, ulnar_corner

    radius = load_template((20.0, 10.0), True).bones["radius"]
    border = ulnar_corner(radius_bone(radius))[2]
    cap_z = radius.vertices[radius.solid][:, 2]
    assert border - 0.4 - 1e-9 <= cap_z.min() <= border + 1.0, (cap_z.min(), border)


def test_a_given_bone_is_used_as_given_and_the_others_carried():
    """A participant's own hamate (issue 54 step 8) replaces the template's; the radial column, not given,
    is still the template's carried by the registration of its capitate (here onto itself: in place)."""
    template = load_template()
    hamate = template.parts["hamate"]
    own = BoneSurface("hamate", hamate.vertices + [0.0, 0.0, -0.5], hamate.faces, hamate.solid)
    bodies = carry_parts({b: template.parts[b] for b in SUPPLIED}, template, True, {"hamate": own})
    assert np.array_equal(bodies["hamate"].vertices, own.vertices)
    np.testing.assert_allclose(bodies["trapezium"].vertices, template.bones["trapezium"].vertices, atol=0.05)
    with pytest.raises(ValueError, match="given bones must be among"):
        carry_parts({b: template.parts[b] for b in SUPPLIED}, template, True, {"capitate": own})
