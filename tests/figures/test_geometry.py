"""The template and model figures (`figures.geometry`)."""

from wrist_env.figures.geometry import PAIR_COLOURS
from wrist_env.model import PAIRS


def test_every_contact_pair_has_its_own_colour_in_the_annotations_figure():
    """The annotations figure colours each articulation's coverage (eight colours for ten articulations
    raised a KeyError on "triquetrohamate" from builder 8, the hamate's)."""
    assert set(PAIR_COLOURS) == set(PAIRS)
    assert len(set(PAIR_COLOURS.values())) == len(PAIRS)
