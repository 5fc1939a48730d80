import numpy as np
import pytest

from wrist_env import design, ligaments, table2
from wrist_env.errors import DesignError


def test_twenty_seven_variables_in_table_2_order():
    assert design.N_DESIGN == 27 and len(design.NAMES) == 27
    assert design.NAMES[0] == "SLIL_v.stiffness" and design.NAMES[11] == "SLIL_v.reference_strain"
    assert design.NAMES[22:] == tuple(f"{n}.injury" for n in ("SLIL_v", "SLIL_p", "SLIL_d", "RSC", "LRL"))
    assert [l.fibres for l in ligaments.LIGAMENTS] == [7, 7, 7, 0, 4, 4, 3, 3, 7, 3, 3]


def test_action_maps_to_mean_plus_three_sd():
    a = np.zeros(27)
    a[2], a[13] = 1.0, -1.0  # SLIL_d stiffness +3 SD, SLIL_v... reference strain of SLIL_p -3 SD
    d = design.from_action(a)
    assert d.stiffness[2] == pytest.approx(79 + 3 * 24)
    assert d.reference_strain[2] == pytest.approx(0.7)
    assert d.stiffness[0] == pytest.approx(33.0)
    np.testing.assert_allclose(design.to_action(d), a)


def test_negative_injury_scalar_is_a_tear():
    a = np.zeros(27)
    a[22:] = [-0.5, 0.5, -1, 1, 0.1]
    torn = design.from_action(a).torn
    assert torn.tolist() == [True, False, True, False, False, False, False, False, False, False, False]


def test_population_is_the_table_2_mean_and_intact():
    p = design.population()
    assert p.stiffness.tolist() == [33, 25, 79, 10, 75, 75, 75, 10, 40, 75, 40]
    assert np.all(p.reference_strain == 1.0) and not p.torn.any()


@pytest.mark.parametrize(
    "bad,match",
    [
        (np.zeros(26), r"shape \(27,\)"),
        (np.r_[np.zeros(26), 1.5], r"LRL.injury=1.5"),
        (np.r_[np.nan, np.zeros(26)], r"SLIL_v.stiffness=nan"),
        (np.zeros(27) + 0.5j, r"real numbers, but got dtype complex128"),
        (np.array(["0.1"] * 27), r"real numbers, but got dtype <U3"),
    ],
)
def test_bad_actions_name_the_value(bad, match):
    with pytest.raises(DesignError, match=match):
        design.from_action(bad)


def test_dict_round_trip_and_z_scores():
    d = design.from_action(np.linspace(-1, 1, 27))
    assert design.Design.from_dict(d.as_dict()).as_dict() == d.as_dict()
    np.testing.assert_allclose(table2.z_scores(d), 3 * np.linspace(-1, 1, 27)[:22])


def test_truncated_material_samples_stay_in_bounds_and_are_normal():
    a = table2.sample_materials(20000, seed=1)
    assert a.shape == (20000, 22) and np.abs(a).max() <= 1.0
    assert np.std(a * 3) == pytest.approx(0.986, abs=0.02)  # SD of N(0,1) truncated at ±3


@pytest.mark.parametrize(
    "edit, match",
    [
        (lambda d: d.update({"SLIL_d.stifness": 1.0}), r"must be among the 27.*'SLIL_d.stifness'"),
        (lambda d: d.update({"SLIL_d.stiffness": "80.0"}), r"must be numbers.*'SLIL_d.stiffness': '80.0'"),
        (lambda d: d.update({"RSC.injury": True}), r"must be numbers.*'RSC.injury': True"),
    ],
    ids=["unknown key", "number as a string", "bool"],
)
def test_a_design_file_with_an_unknown_key_or_a_non_number_is_named(tmp_path, edit, match):
    import json
    import re

    from wrist_env.errors import DesignError

    data = design.population().as_dict()
    edit(data)
    path = tmp_path / "design.json"
    path.write_text(json.dumps(data))
    with pytest.raises(DesignError, match=re.escape(str(path)) + ": design variables " + match):
        design.read_json(path)


@pytest.mark.parametrize("data, match", [(None, "but got NoneType."), ([0.5] * 27, r"but got list \[0.5")])
def test_a_design_that_is_not_a_mapping_is_named(data, match):
    """`Design.from_dict(None)` was a TypeError from deep inside ("argument of type 'NoneType' ...")."""
    with pytest.raises(DesignError, match="a design is a mapping of the 27 variables .*" + match):
        design.Design.from_dict(data)


def test_an_empty_batch_of_actions_is_no_designs_but_a_wrong_width_is_named():
    assert design.from_actions(np.zeros((0, design.N_DESIGN))) == [] and design.from_actions([]) == []
    with pytest.raises(DesignError, match=r"shape \(n, 27\), but got \(0, 5\)"):
        design.from_actions(np.zeros((0, 5)))


def test_the_capitohamate_bands_stiffness_is_ritt_1996s_distraction_shared_by_three():
    """Each capitohamate interosseous band (fixed, outside the 27 variables): Ritt 1996's 20 N over the
    joint's 0.3 mm distraction, shared equally by the deep, dorsal and palmar bands (66.7 N/mm for the
    three in parallel, 22.2 N/mm each)."""
    fixed = {lig.name: lig for lig in ligaments.FIXED_LIGAMENTS}
    assert ligaments.HAMATE_LIGAMENTS == ("CH_deep", "CH_d", "CH_p")
    assert ligaments.STIFFNESS_CH == pytest.approx(20.0 / 0.3 / 3) == pytest.approx(22.22, abs=0.01)
    for name in ligaments.HAMATE_LIGAMENTS:
        assert fixed[name].stiffness_mean == ligaments.STIFFNESS_CH and not fixed[name].injurable
        assert name not in ligaments.LIGAMENT_NAMES and name in ligaments.ALL_LIGAMENT_NAMES
    assert sum(
        fixed[n].stiffness_mean for n in ligaments.HAMATE_LIGAMENTS
    ) * ligaments.CH_DISTRACTION_MM == pytest.approx(ligaments.CH_RIG_FORCE_N)
    stiffness, strain, torn = design.ligament_arrays(design.population())
    k = ligaments.ALL_LIGAMENT_NAMES.index("CH_deep")
    assert stiffness[k] == ligaments.STIFFNESS_CH and strain[k] == 1.0 and not torn[k] and design.N_DESIGN == 27
