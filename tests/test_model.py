"""The `Model`'s layout checks: a model of another body or pair count is refused by name, never simulated
(the kernels do not check bounds)."""

from dataclasses import replace

import numpy as np
import pytest

from wrist_env.errors import InputError
from wrist_env.model import BONES, PAIRS


def test_a_model_with_another_body_count_is_refused_naming_the_field(built):
    p1 = built("P1")
    with pytest.raises(InputError, match=r"model 'P1': com has shape \(4, 3\).*\(%d, 3\)" % len(BONES)):
        replace(p1, com=p1.com[:4])
    with pytest.raises(InputError, match="sample_offsets"):
        replace(p1, sample_offsets=np.append(p1.sample_offsets, p1.sample_offsets[-1]))
    assert len(p1.sample_offsets) == len(PAIRS) + 1


def test_a_fibre_on_a_body_the_model_lacks_is_refused(built):
    p1 = built("P1")
    bones = p1.fibre_bones.copy()
    bones[0, 1] = len(BONES)
    with pytest.raises(InputError, match="fibre_bones holds body index"):
        replace(p1, fibre_bones=bones)


def test_the_hamate_is_a_free_body_of_its_own_carried_by_the_capitate():
    """The hamate (issue 54, step 2) free in 6 DOF beside the scaphoid, the lunate, the radial column and the
    triquetrum, carried from the template with the capitate (not supplied by a folder), in contact with the
    capitate and with the triquetrum (the template's lunate is type I: no lunohamate pair)."""
    from wrist_env.model import (
        ARTICULATIONS,
        BODY_PARTS,
        CAPITATE,
        CARRIED,
        CARRIED_WITH,
        FREE,
        HAMATE,
        PAIR_BONES,
        PARTS,
        SUPPLIED,
        TRAPEZIUM,
        TRIQUETRUM,
    )

    assert BONES[HAMATE] == "hamate"
    assert HAMATE in FREE and CAPITATE not in FREE and CARRIED == (TRAPEZIUM, HAMATE)
    assert BODY_PARTS["hamate"] == ("hamate",) and BODY_PARTS["capitate"] == ("capitate",)
    assert CARRIED_WITH["hamate"] == "capitate" and "hamate" not in SUPPLIED and len(PARTS) == 9
    assert PAIR_BONES[PAIRS.index("capitohamate")].tolist() == [HAMATE, CAPITATE]
    assert PAIR_BONES[PAIRS.index("triquetrohamate")].tolist() == [TRIQUETRUM, HAMATE]
    assert ARTICULATIONS["triquetrohamate"] == ("triquetrohamate", ("triquetrum",))
    assert "lunohamate" not in ARTICULATIONS


def test_the_triquetrum_is_a_free_proximal_row_body_of_its_own_carried_by_the_lunate():
    """Eight bodies: the triquetrum (issue 54, step 3) free in 6 DOF, a proximal-row bone (not `CARRIED`: its
    dislocation is measured from its neutral place), carried from the template with the lunate, the lunate a
    body of one bone; in contact with the lunate, the hamate and the ulna (the TFCC), each its own pair."""
    from wrist_env.model import (
        ARTICULATIONS,
        BODY_PARTS,
        CARRIED,
        CARRIED_WITH,
        FREE,
        HAMATE,
        LUNATE,
        N_BODIES,
        PAIR_BONES,
        SUPPLIED,
        TFCC_PAIRS,
        TRIQUETRUM,
        ULNA,
    )

    assert N_BODIES == len(BONES) == 8 and BONES[TRIQUETRUM] == "triquetrum" and TRIQUETRUM == N_BODIES - 1
    assert TRIQUETRUM in FREE and TRIQUETRUM not in CARRIED
    assert BODY_PARTS["lunate"] == ("lunate",) and BODY_PARTS["triquetrum"] == ("triquetrum",)
    assert CARRIED_WITH["triquetrum"] == "lunate" and "triquetrum" not in SUPPLIED
    assert PAIR_BONES[PAIRS.index("lunotriquetral")].tolist() == [TRIQUETRUM, LUNATE]
    assert PAIR_BONES[PAIRS.index("ulnotriquetral")].tolist() == [TRIQUETRUM, ULNA]
    assert PAIR_BONES[PAIRS.index("ulnolunate")].tolist() == [LUNATE, ULNA]
    assert PAIR_BONES[PAIRS.index("triquetrohamate")].tolist() == [TRIQUETRUM, HAMATE]
    assert TFCC_PAIRS == ("ulnolunate", "ulnotriquetral") and "ulnocarpal" not in PAIRS
    assert ARTICULATIONS["ulnotriquetral"] == ("ulnotriquetral", ("triquetrum",))
    assert ARTICULATIONS["radiolunate"] == ("radiolunate", ("lunate",))


def test_a_built_model_gives_the_hamate_mass_a_grid_contacts_and_its_capitohamate_bands(built):
    """P1 as built: the hamate has mass and a contact grid, samples on both of its pairs, and the three
    capitohamate bands (3 fibres each) run from it to the capitate; the TH ligament ends on it."""
    from wrist_env.design import ALL_LIGAMENT_NAMES, HAMATE_LIGAMENTS
    from wrist_env.model import CAPITATE, HAMATE, TRIQUETRUM

    p1 = built("P1")
    assert p1.mass[HAMATE] > 0 and p1.grid(BONES[HAMATE]).size > 0
    for pair in ("capitohamate", "triquetrohamate"):
        k = PAIRS.index(pair)
        assert p1.sample_offsets[k + 1] - p1.sample_offsets[k] > 20, pair
    for name in HAMATE_LIGAMENTS + ("TH",):
        mine = p1.fibre_ligament == ALL_LIGAMENT_NAMES.index(name)
        expected = [HAMATE, CAPITATE] if name != "TH" else [TRIQUETRUM, HAMATE]
        assert mine.sum() == 3 and (p1.fibre_bones[mine] == expected).all(), name
        assert np.linalg.norm(p1.fibre_insertion[mine] - p1.fibre_origin[mine], axis=1).max() < 6.0 or name == "TH"


def test_a_built_model_gives_the_triquetrum_mass_contacts_and_its_ligaments(built):
    """P1 as built: the triquetrum has mass and no grid (it is the sample body of each of its pairs), samples
    on its three pairs, the lunotriquetral bands (3 fibres each, across a joint of 1-2 mm) run from it to the
    lunate, the UT from the ulna to it, and the DRC, TC and TH leave from it; the lunate's centroid is its
    centre of mass (a body of one bone)."""
    from wrist_env.design import ALL_LIGAMENT_NAMES, TRIQUETRUM_LIGAMENTS
    from wrist_env.model import LUNATE, RADIUS, TRIQUETRUM, ULNA

    p1 = built("P1")
    assert p1.mass[TRIQUETRUM] > 0 and p1.grid(BONES[TRIQUETRUM]).size == 0
    np.testing.assert_allclose(p1.centroid[LUNATE], p1.com[LUNATE])
    for pair in ("lunotriquetral", "ulnotriquetral", "triquetrohamate"):
        k = PAIRS.index(pair)
        assert p1.sample_offsets[k + 1] - p1.sample_offsets[k] > 20, pair
    expected = {"LT_v": [TRIQUETRUM, LUNATE], "LT_p": [TRIQUETRUM, LUNATE], "LT_d": [TRIQUETRUM, LUNATE]}
    expected |= {"UT": [ULNA, TRIQUETRUM], "DRC": [RADIUS, TRIQUETRUM], "TC": [TRIQUETRUM, 4]}
    for name in TRIQUETRUM_LIGAMENTS + ("DRC", "TC"):
        mine = p1.fibre_ligament == ALL_LIGAMENT_NAMES.index(name)
        assert mine.sum() == 3 and (p1.fibre_bones[mine] == expected[name]).all(), name
        if name.startswith("LT"):
            assert np.linalg.norm(p1.fibre_insertion[mine] - p1.fibre_origin[mine], axis=1).max() < 6.0, name
