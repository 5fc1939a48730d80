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


def test_fixed_midcarpal_ligaments_join_the_triquetrum_to_the_distal_row():
    """TC and TH (design.FIXED_LIGAMENTS) run palmar, from the triquetrum to the capitate neck and the
    hamate body; they are resolved only on bodies that carry those bones (the distal row)."""
    from wrist_env.anatomy.annotations import template_annotations
    from wrist_env.design import COLUMN_LIGAMENTS, FIXED_LIGAMENTS
    from wrist_env.model import BODY_PARTS

    data = read_annotation_data()["ligaments"]
    with_row, without = template_annotations((20.0, 10.0), True), template_annotations()
    for lig in (lig for lig in FIXED_LIGAMENTS if lig.name not in COLUMN_LIGAMENTS):  # the column's: their own
        spec = data[lig.name]
        assert spec["origin"]["part"] == "triquetrum" and spec["insertion"]["bone"] == "capitate"
        assert spec["origin"]["centre_mm"][0] > 5.0 and spec["insertion"]["centre_mm"][0] > 5.0  # palmar (x volar)
        assert lig.name not in without.sites
        origin, insertion = with_row.sites[lig.name]
        assert origin.mask.sum() >= lig.fibres and insertion.mask.sum() >= lig.fibres
        part = spec["insertion"].get("part", "capitate")
        from wrist_env.anatomy.template import load_template

        body = load_template((20.0, 10.0), True).bones["capitate"]
        assert (body.part[insertion.mask] == BODY_PARTS["capitate"].index(part)).all(), lig.name
