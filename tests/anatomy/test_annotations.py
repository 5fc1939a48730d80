import numpy as np
import pytest

from wrist_env.anatomy.annotations import ARTICULATIONS, read_annotation_data, template_annotations
from wrist_env.design import LIGAMENTS


@pytest.fixture(scope="module")
def ann():
    return template_annotations()


def test_every_articulation_is_covered_on_both_bones(ann):
    for art in ARTICULATIONS:
        a, b, ma, mb = ann.coverage[art]
        assert ma.sum() > 100 and mb.sum() > 100, art


def test_every_ligament_site_has_room_for_its_fibres(ann):
    for lig in LIGAMENTS:
        origin, insertion = ann.sites[lig.name]
        need = max(lig.fibres, 5)
        assert origin.mask.sum() >= need and insertion.mask.sum() >= need, lig.name
        assert origin.bone != insertion.bone


def test_site_bones_follow_the_anatomy():
    data = read_annotation_data()["ligaments"]
    ends = {name: (d["origin"]["bone"], d["insertion"]["bone"]) for name, d in data.items()}
    assert ends["SLIL_v"] == ends["SLIL_p"] == ends["SLIL_d"] == ("scaphoid", "lunate")
    assert ends["RSC"] == ("radius", "capitate")
    assert ends["UCL"] == ("ulna", "capitate") and ends["UL"] == ("ulna", "lunate")
    # SLIL regions: volar site volar of the dorsal one, proximal site most proximal
    c = {k: np.array(d["origin"]["centre_mm"]) for k, d in data.items()}
    assert c["SLIL_v"][0] > c["SLIL_p"][0] > c["SLIL_d"][0]
    assert c["SLIL_p"][1] > max(c["SLIL_v"][1], c["SLIL_d"][1])
    assert c["DRC"][0] < 0 < c["LRL"][0]  # dorsal vs volar radiocarpal ligaments
