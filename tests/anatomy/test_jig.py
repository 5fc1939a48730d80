"""The hand loaded axially as in a jig (`anatomy.jig`): the CMC facets measured on myo-sim's metacarpals
against the hand's anatomy, and the load's lines on a model."""

import numpy as np
import pytest

from wrist_env.anatomy import jig
from wrist_env.model import BODY_PARTS, BONES


def test_each_distal_carpal_faces_the_metacarpals_it_bears():
    """The carpometacarpal joints (Gray's Anatomy): the first metacarpal on the trapezium, the second on the
    trapezoid, the third on the capitate, the fifth on the hamate (the fourth on the hamate and the capitate)."""
    facets = jig.cmc_facets()
    assert set(facets) == set(jig.DISTAL_CARPALS)
    assert "firstmc_r" in facets["trapezium"]["metacarpals"]
    assert "secondmc_r" in facets["trapezoid"]["metacarpals"]
    assert "thirdmc_r" in facets["capitate"]["metacarpals"]
    assert {"fourthmc_r", "fifthmc_r"} <= set(facets["hamate"]["metacarpals"])
    for carpal, f in facets.items():
        assert f["area"] > 20.0, (carpal, f["area"])  # mm²: a joint, not a touching vertex


def test_the_jig_loads_each_distal_carpal_along_the_radius_by_its_cmc_area(built):
    """One line per distal carpal on the body it belongs to, along +y (proximal, the radius' axis), shared by
    CMC area; the driver's lines are these (`drivers.loads(model, "jig")`)."""
    from wrist_env.solver import drivers

    model = built("P1")
    loads = drivers.loads(model, "jig")
    facets = jig.cmc_facets()
    area = np.array([facets[c]["area"] for c in jig.DISTAL_CARPALS])
    np.testing.assert_allclose(loads.share, area / area.sum())
    assert loads.share.sum() == pytest.approx(1.0)
    np.testing.assert_array_equal(loads.direction, np.tile([0.0, 1.0, 0.0], (4, 1)))
    owners = [BONES.index(next(b for b in BONES if c in BODY_PARTS[b])) for c in jig.DISTAL_CARPALS]
    assert list(loads.body) == owners and loads.name == "jig"
