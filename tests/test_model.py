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
    """Seven bodies: the hamate (issue 54, step 2) free in 6 DOF beside the scaphoid, the lunate body and the
    radial column, carried from the template with the capitate (not supplied by a folder), in contact
    with the capitate and with the lunate body (its triquetrum; its lunate where a type II lunate reaches)."""
    from wrist_env.model import (
        ARTICULATIONS,
        BODY_PARTS,
        CAPITATE,
        CARRIED,
        CARRIED_WITH,
        FREE,
        HAMATE,
        LUNATE,
        N_BODIES,
        PAIR_BONES,
        PARTS,
        SUPPLIED,
        TRAPEZIUM,
    )

    assert N_BODIES == len(BONES) == 7 and BONES[HAMATE] == "hamate" and HAMATE == N_BODIES - 1
    assert HAMATE in FREE and CAPITATE not in FREE and CARRIED == (TRAPEZIUM, HAMATE)
    assert BODY_PARTS["hamate"] == ("hamate",) and BODY_PARTS["capitate"] == ("capitate",)
    assert CARRIED_WITH["hamate"] == "capitate" and "hamate" not in SUPPLIED and len(PARTS) == 9
    assert PAIR_BONES[PAIRS.index("capitohamate")].tolist() == [HAMATE, CAPITATE]
    assert PAIR_BONES[PAIRS.index("triquetrohamate")].tolist() == [LUNATE, HAMATE]
    assert ARTICULATIONS["triquetrohamate"] == ("triquetrohamate", ("triquetrum",))
    assert ARTICULATIONS["lunohamate"] == ("triquetrohamate", ("lunate",))


def test_a_built_model_gives_the_hamate_mass_a_grid_contacts_and_its_capitohamate_bands(built):
    """P1 as built: the hamate has mass and a contact grid, samples on both of its pairs, and the three
    capitohamate bands (3 fibres each) run from it to the capitate; the TH ligament ends on it."""
    from wrist_env.ligaments import ALL_LIGAMENT_NAMES, HAMATE_LIGAMENTS
    from wrist_env.model import CAPITATE, HAMATE, LUNATE

    p1 = built("P1")
    assert p1.mass[HAMATE] > 0 and p1.grid(BONES[HAMATE]).size > 0
    for pair in ("capitohamate", "triquetrohamate"):
        k = PAIRS.index(pair)
        assert p1.sample_offsets[k + 1] - p1.sample_offsets[k] > 20, pair
    for name in HAMATE_LIGAMENTS + ("TH",):
        mine = p1.fibre_ligament == ALL_LIGAMENT_NAMES.index(name)
        expected = [HAMATE, CAPITATE] if name != "TH" else [LUNATE, HAMATE]
        assert mine.sum() == 3 and (p1.fibre_bones[mine] == expected).all(), name
        assert np.linalg.norm(p1.fibre_insertion[mine] - p1.fibre_origin[mine], axis=1).max() < 6.0 or name == "TH"
