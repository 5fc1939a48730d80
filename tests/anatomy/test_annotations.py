import numpy as np
import pytest

from wrist_env.anatomy.annotations import read_annotation_data, template_annotations
from wrist_env.ligaments import LIGAMENTS
from wrist_env.model import PAIRS


@pytest.fixture(scope="module")
def ann():
    return template_annotations()


def test_every_articulation_is_covered_on_both_bones(ann):
    """Each articulation has cartilage on both bones; the triquetrohamate one only with the distal row (the
    lunate body's triquetrum: the template's lunate, a type I lunate, comes no nearer the hamate than 3.8 mm)."""
    with_row = template_annotations((20.0, 10.0), True)
    for art in PAIRS:
        for coverage in (ann.coverage, with_row.coverage):
            a, b, ma, mb = coverage[art]
            if art == "triquetrohamate" and coverage is ann.coverage:
                assert ma.sum() == 0, art
                continue
            least = 30 if art == "triquetrohamate" else 100
            assert ma.sum() > least and mb.sum() > least, (art, ma.sum(), mb.sum())


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
    """TC and TH (ligaments.FIXED_LIGAMENTS) run palmar, from the triquetrum to the capitate neck and the
    hamate body (a body of its own); they are resolved only on bodies that carry the triquetrum (the
    distal row)."""
    from wrist_env.anatomy.annotations import template_annotations
    from wrist_env.anatomy.template import load_template
    from wrist_env.ligaments import FIXED_LIGAMENTS

    data = read_annotation_data()["ligaments"]
    with_row, without = template_annotations((20.0, 10.0), True), template_annotations()
    bones = load_template((20.0, 10.0), True).bones
    for lig in (lig for lig in FIXED_LIGAMENTS if lig.name in ("TC", "TH")):
        spec = data[lig.name]
        assert spec["origin"]["part"] == "triquetrum"
        assert spec["insertion"]["bone"] == {"TC": "capitate", "TH": "hamate"}[lig.name]
        assert "part" not in spec["insertion"]
        assert spec["origin"]["centre_mm"][0] > 5.0 and spec["insertion"]["centre_mm"][0] > 5.0  # palmar (x volar)
        assert lig.name not in without.sites
        origin, insertion = with_row.sites[lig.name]
        assert origin.mask.sum() >= lig.fibres and insertion.mask.sum() >= lig.fibres
        assert insertion.bone == spec["insertion"]["bone"] and insertion.mask.shape == (
            len(bones[insertion.bone].vertices),
        )


@pytest.mark.parametrize("distal_row", [False, True])
def test_the_capitohamate_bands_span_the_joint_at_its_dorsal_palmar_and_deep_distal_parts(distal_row):
    """CH_d, CH_p and CH_deep (ligaments.HAMATE_LIGAMENTS, Ritt 1996) run from the hamate's side of the
    capitohamate joint to the capitate's, in every variant: each site within 2.5 mm of the other bone
    (the facing sides), the dorsal band dorsal of the deep one and the palmar band palmar of it (x volar),
    the deep band the most distal (y proximal), each band across the joint (mostly along the radioulnar
    axis z, the hamate ulnar), 2–4 mm long."""
    from scipy.spatial import cKDTree

    from wrist_env.anatomy.template import load_template
    from wrist_env.ligaments import HAMATE_LIGAMENTS

    data = read_annotation_data()["ligaments"]
    parts = load_template().parts
    near = {b: cKDTree(parts[b].vertices) for b in ("hamate", "capitate")}
    centre = {}
    for name in HAMATE_LIGAMENTS:
        o, i = data[name]["origin"], data[name]["insertion"]
        assert (o["bone"], i["bone"]) == ("hamate", "capitate") and "part" not in o and "part" not in i
        a, b = np.array(o["centre_mm"]), np.array(i["centre_mm"])
        assert near["capitate"].query(a)[0] < 2.5 and near["hamate"].query(b)[0] < 2.5, name
        band = b - a
        assert 2.0 < np.linalg.norm(band) < 4.0 and band[2] > 0.8 * np.linalg.norm(band), (name, band)
        centre[name] = (a + b) / 2
    assert centre["CH_d"][0] < centre["CH_deep"][0] < centre["CH_p"][0]
    assert centre["CH_deep"][1] < min(centre["CH_d"][1], centre["CH_p"][1])
    sites = template_annotations((20.0, 10.0), distal_row).sites
    for name in HAMATE_LIGAMENTS:
        origin, insertion = sites[name]
        assert (origin.bone, insertion.bone) == ("hamate", "capitate")
        assert origin.mask.sum() >= 5 and insertion.mask.sum() >= 5, name
