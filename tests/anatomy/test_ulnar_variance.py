"""The ulnar variance's corner rule and the ulna's seat (issue 54) against a closed form: boxes at known levels."""

import numpy as np
import pytest
import trimesh

from wrist_env.anatomy.template import BoneSurface
from wrist_env.anatomy.ulnar_variance import HEAD_WIDTH_MM, radius_bone, seat_ulna, ulnar_variance


def box(x, y, z) -> trimesh.Trimesh:
    """An axis-aligned box spanning the (low, high) ranges x, y, z (mm, RCS: y proximal, z radial)."""
    lo, hi = np.array([x[0], y[0], z[0]]), np.array([x[1], y[1], z[1]])
    return trimesh.creation.box(extents=hi - lo, transform=trimesh.transformations.translation_matrix((lo + hi) / 2))


RADIUS = box((-10, 10), (0, 30), (0, 20))  # its ulnar corner at y = 0, z = 0; the shaft runs proximal (+y)


def ulna(head_y: float) -> trimesh.Trimesh:
    """The ulnar head's dome at y = head_y, its radial border 2 mm ulnar of the radius, and a styloid 10–14 mm
    ulnar of that border (beyond `HEAD_WIDTH_MM`) reaching 5 mm further distal, which the rule leaves out."""
    head = box((-6, 6), (head_y, head_y + 30), (-9, -2))
    styloid = box((-2, 2), (head_y - 5, head_y + 5), (-16, -12))
    return trimesh.util.concatenate([head, styloid])


@pytest.mark.parametrize("head_y", [-2.5, 0.0, 1.25, 4.9])
def test_the_corner_rule_gives_the_level_difference_of_two_boxes(head_y):
    """The radius' ulnar corner at y = 0 and the head's dome at head_y: variance −head_y (+ ulna plus:
    a head more distal, at lower y, than the corner)."""
    assert HEAD_WIDTH_MM < 10.0  # the styloid is outside the head's window
    v = ulnar_variance(RADIUS.vertices, ulna(head_y).vertices)
    assert v.variance_mm == pytest.approx(-head_y) and v.corner_y == 0.0 and v.head_y == pytest.approx(head_y)


def test_the_corner_is_the_distal_ends_most_ulnar_point():
    """A radius shaft that reaches further ulnar proximally (y ≥ 6 mm) does not hold the corner."""
    radius = trimesh.util.concatenate([RADIUS, box((-5, 5), (8, 40), (-1, 0))])
    assert ulnar_variance(radius.vertices, ulna(1.0).vertices).corner_y == 0.0


@pytest.mark.parametrize("target", [-2.5, 0.0, 0.26, 2.5])
def test_the_ulna_is_seated_at_the_variance_asked(target):
    """Moved along y only, by the difference, so the rule then reads the value asked; the radius stays."""
    u = ulna(3.0)
    bones = {
        "radius": BoneSurface("radius", RADIUS.vertices, RADIUS.faces, np.ones(len(RADIUS.vertices), bool)),
        "ulna": BoneSurface("ulna", u.vertices, u.faces, np.zeros(len(u.vertices), bool)),
    }
    moved, done = seat_ulna(bones, target)
    assert moved["radius"] is bones["radius"]
    shift = moved["ulna"].vertices - bones["ulna"].vertices
    np.testing.assert_allclose(shift, np.tile([0.0, -3.0 - target, 0.0], (len(shift), 1)), atol=1e-12)
    assert ulnar_variance(RADIUS.vertices, moved["ulna"].vertices).variance_mm == pytest.approx(target)
    assert done == {"given": -3.0, "seated": pytest.approx(target), "shift_mm": pytest.approx(-3.0 - target)}


def test_the_corner_is_the_ulnar_borders_most_distal_point():
    """A lip 0.5 mm ulnar of the distal end, starting 2 mm proximal of it, is on the ulnar border (within 1 mm
    of the most ulnar point), and the corner is the border's most distal point: y = 0, not the lip's 2."""
    radius = trimesh.util.concatenate([RADIUS, box((-5, 5), (2, 5), (-0.5, 0))])
    assert ulnar_variance(radius.vertices, ulna(1.0).vertices).corner_y == 0.0


def test_no_corner_or_no_ulna_is_said():
    with pytest.raises(ValueError, match="no radius vertex less than 6 mm proximal"):
        ulnar_variance(RADIUS.vertices + [0, 10, 0], ulna(0.0).vertices)
    with pytest.raises(ValueError, match="no ulna vertex"):
        ulnar_variance(RADIUS.vertices, np.zeros((0, 3)))


def test_the_corner_is_read_on_the_radius_bone_not_its_rebuilt_fossae():
    """A radius with an articular solid and other vertices (a built-in's: the rebuilt fossae on myo-sim's
    distal radius) is read on the other vertices; one all solid or none solid (a folder's) on all."""
    v = np.arange(12.0).reshape(4, 3)
    mixed = BoneSurface("radius", v, np.zeros((0, 3), np.int64), np.array([True, True, False, False]))
    np.testing.assert_array_equal(radius_bone(mixed), v[2:])
    for solid in (np.ones(4, bool), np.zeros(4, bool)):
        np.testing.assert_array_equal(radius_bone(BoneSurface("radius", v, np.zeros((0, 3), np.int64), solid)), v)


def test_the_build_seats_a_participants_ulna_before_it_is_used():
    """On P1's bones (`pipeline._seat_ulna`, which `build_model` calls before the morphs): as given, the
    step-0 reading on myo-sim's radius (−3.07 mm); asked +1.25, the ulna moves 4.32 mm distal and reads
    +1.25; where the rule finds no corner, a `BuildError` only when a variance is asked."""
    from wrist_env.anatomy.template import closed
    from wrist_env.builder.pipeline import _seat_ulna
    from wrist_env.errors import BuildError
    from wrist_env.participants import registry

    bones = dict(registry.bones("P1"))
    bones["ulna"] = closed(bones["ulna"])
    same, as_given = _seat_ulna("P1", bones, None)
    assert same is bones and as_given["given"] == pytest.approx(-3.07, abs=0.005) and as_given["shift_mm"] == 0.0
    moved, done = _seat_ulna("P1", bones, 1.25)
    assert done["seated"] == pytest.approx(1.25) and done["shift_mm"] == pytest.approx(-4.32, abs=0.005)
    assert ulnar_variance(radius_bone(moved["radius"]), moved["ulna"].vertices).variance_mm == pytest.approx(1.25)
    r = bones["radius"]
    away = {**bones, "radius": BoneSurface("radius", r.vertices + [0, 50, 0], r.faces, r.solid)}
    assert _seat_ulna("P1", away, None)[1] is None  # no corner: as given, nothing recorded
    with pytest.raises(BuildError, match="ulnar variance 1.25 mm cannot be seated: no radius vertex"):
        _seat_ulna("P1", away, 1.25)
