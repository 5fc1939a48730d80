"""The template and model figures (`figures.geometry`)."""

from wrist_env.anatomy.annotations import ARTICULATIONS
from wrist_env.figures.geometry import ARTICULATION_COLOURS


def test_every_articulation_has_its_own_colour_in_the_annotations_figure():
    """The annotations figure colours each articulation's coverage (eight colours for ten articulations
    raised a KeyError on 'triquetrohamate' from builder 8, the hamate's)."""
    assert set(ARTICULATION_COLOURS) == set(ARTICULATIONS)
    assert len(set(ARTICULATION_COLOURS.values())) == len(ARTICULATIONS)
