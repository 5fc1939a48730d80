import numpy as np
import pytest

from wrist_env.anatomy.annotations import ARTICULATIONS, read_annotation_data, template_annotations
from wrist_env.design import LIGAMENTS


@pytest.fixture(scope="module")
def ann():
    return template_annotations()


def test_every_articulation_is_covered_on_both_bones(ann):
    """Each articulation has cartilage on both bones in both variants (the triquetrum is a body of its own in
    both: a model without the distal row drops its pairs, `builder.pipeline.ABSENT_WITHOUT_DISTAL_ROW`)."""
    with_row = template_annotations((20.0, 10.0), True)
    for art in ARTICULATIONS:
        for coverage in (ann.coverage, with_row.coverage):
            a, b, ma, mb = coverage[art]
            least = 30 if art in ("triquetrohamate", "ulnotriquetral") else 100
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
    """TC and TH (design.FIXED_LIGAMENTS) run palmar, from the triquetrum (a body of its own) to the capitate
    neck and the hamate body (a body of its own); they are resolved only with the distal row (without it
    the triquetrum is detached: `model.DETACHED_WITHOUT_DISTAL_ROW`)."""
    from wrist_env.anatomy.annotations import template_annotations
    from wrist_env.anatomy.template import load_template
    from wrist_env.design import FIXED_LIGAMENTS

    data = read_annotation_data()["ligaments"]
    with_row, without = template_annotations((20.0, 10.0), True), template_annotations()
    bones = load_template((20.0, 10.0), True).bones
    for lig in (lig for lig in FIXED_LIGAMENTS if lig.name in ("TC", "TH")):
        spec = data[lig.name]
        assert spec["origin"]["bone"] == "triquetrum" and "part" not in spec["origin"]
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
    """CH_d, CH_p and CH_deep (design.HAMATE_LIGAMENTS, Ritt 1996) run from the hamate's side of the
    capitohamate joint to the capitate's, in every variant: each site within 2.5 mm of the other bone
    (the facing sides), the dorsal band dorsal of the deep one and the palmar band palmar of it (x volar),
    the deep band the most distal (y proximal), each band across the joint (mostly along the radioulnar
    axis z, the hamate ulnar), 2–4 mm long."""
    from scipy.spatial import cKDTree

    from wrist_env.anatomy.template import load_template
    from wrist_env.design import HAMATE_LIGAMENTS

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


def test_the_lunotriquetral_bands_span_the_joint_at_its_palmar_proximal_and_dorsal_rims():
    """LT_v, LT_p and LT_d (design.TRIQUETRUM_LIGAMENTS, Ritt 1998: a C-shaped ligament like the SLIL) run
    from the triquetrum to the lunate, each end within 3 mm of the other bone, the palmar band palmar of the
    proximal and the dorsal dorsal of it (x volar), the proximal band the most proximal (y proximal), each
    2-5 mm long; the UT from the ulna's palmar-distal head to the palmar triquetrum, ulnar to the UL's
    origin. All resolved with the distal row, none without it (the triquetrum detached), and the DRC then
    inserts on the lunate instead (its `without_part`)."""
    from scipy.spatial import cKDTree

    from wrist_env.anatomy.template import load_template
    from wrist_env.design import TRIQUETRUM_LIGAMENTS

    data = read_annotation_data()["ligaments"]
    parts = load_template().parts
    near = {b: cKDTree(parts[b].vertices) for b in ("triquetrum", "lunate")}
    centre = {}
    for name in ("LT_v", "LT_p", "LT_d"):
        o, i = data[name]["origin"], data[name]["insertion"]
        assert (o["bone"], i["bone"]) == ("triquetrum", "lunate")
        a, b = np.array(o["centre_mm"]), np.array(i["centre_mm"])
        assert near["lunate"].query(a)[0] < 3.0 and near["triquetrum"].query(b)[0] < 3.0, name
        assert 2.0 < np.linalg.norm(b - a) < 5.0, name
        centre[name] = (a + b) / 2
    assert centre["LT_d"][0] < centre["LT_p"][0] < centre["LT_v"][0]
    assert centre["LT_p"][1] > max(centre["LT_v"][1], centre["LT_d"][1])
    ut, ul = data["UT"], data["UL"]
    assert (ut["origin"]["bone"], ut["insertion"]["bone"]) == ("ulna", "triquetrum")
    assert ut["origin"]["centre_mm"][2] < ul["origin"]["centre_mm"][2]  # ulnar (z radial) to the UL
    assert ut["origin"]["centre_mm"][0] > 0 and ut["insertion"]["centre_mm"][0] > 5.0  # palmar
    with_row, without = template_annotations((20.0, 10.0), True), template_annotations((20.0, 10.0), False)
    for name in TRIQUETRUM_LIGAMENTS:
        origin, insertion = with_row.sites[name]
        assert origin.mask.sum() >= 5 and insertion.mask.sum() >= 5, name
        assert name not in without.sites
    assert with_row.sites["DRC"][1].bone == "triquetrum" and without.sites["DRC"][1].bone == "lunate"
