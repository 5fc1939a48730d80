"""The figures' palette covers the model: every body and every ligament, the fixed ones included (a
ligament without a colour was dropped by `zip` and its figure raised a KeyError)."""

from wrist_env.design import ALL_LIGAMENT_NAMES
from wrist_env.figures import draw
from wrist_env.model import BONES


def test_every_body_and_ligament_has_its_own_colour():
    assert set(draw.BONE_COLOUR) == set(BONES)
    assert set(draw.LIGAMENT_COLOURS) == set(ALL_LIGAMENT_NAMES)
    assert len(set(draw.LIGAMENT_COLOURS.values())) == len(ALL_LIGAMENT_NAMES)
