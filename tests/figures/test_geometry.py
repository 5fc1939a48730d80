"""The template and model figures (`figures.geometry`)."""


def test_every_articulation_has_its_own_colour_in_the_annotations_figure():
    """The annotations figure colours each articulation's coverage (it raised a KeyError on the pairs past
    its eight colours: capitohamate and triquetrohamate from builder 8, then the triquetrum's)."""
    from wrist_env.figures.geometry import ARTICULATION_COLOURS
    from wrist_env.model import PAIRS

    assert set(ARTICULATION_COLOURS) == set(PAIRS)
    assert len(set(ARTICULATION_COLOURS.values())) == len(PAIRS)
