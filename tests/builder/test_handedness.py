"""A wrong `side` is refused before the morph: the template's bones fit the participant's closer mirrored."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from wrist_env.anatomy.template import load_template
from wrist_env.builder.handedness import MIRROR, check_side, side_misfits, similarity_misfit
from wrist_env.builder.params import BuildParams
from wrist_env.errors import BuildError
from wrist_env.participants import registry


class _Bone:
    def __init__(self, vertices):
        self.vertices = vertices


@pytest.fixture(scope="module")
def template():
    return load_template(*BuildParams().anatomy).bones


def test_a_similar_copy_fits_exactly_and_its_mirror_image_does_not(template):
    """A rotated (20°), scaled (1.1) and shifted copy of the template's lunate with its triquetrum (the lunate
    body until builder 8; the lunate alone is nearer its own mirror image, 0.73 mm) is fitted back to within
    0.01 mm (Umeyama's closed form each iteration); its mirror image stays over 1 mm away."""
    v = np.vstack([template["lunate"].vertices, template["triquetrum"].vertices])
    turn = Rotation.from_rotvec(np.radians(20) * np.array([0.3, 0.5, 0.8]) / np.linalg.norm([0.3, 0.5, 0.8]))
    copy = 1.1 * turn.apply(v) + [4.0, -2.0, 7.0]
    assert similarity_misfit(v, copy) < 0.01
    assert similarity_misfit(v * MIRROR, copy) > 1.0


@pytest.mark.parametrize("name", ["P1", "P2", "P3"])
def test_the_builtins_are_right_wrists_and_mirrored_left_ones(template, name):
    bones = registry.bones(name)
    misfits = check_side(name, template, bones)
    assert all(as_is < mirror for as_is, mirror in misfits.values()), misfits
    mirrored = {b: _Bone(bone.vertices * MIRROR) for b, bone in bones.items()}
    assert all(as_is > mirror for as_is, mirror in side_misfits(template, mirrored).values())
    n = len(bones)  # every body (`model.BONES`)
    with pytest.raises(
        BuildError, match=rf"participant '{name}': the bones are the other hand's: .* {n} of {n} .*`side`"
    ):
        check_side(name, template, mirrored)
