"""The tendon loads at their myo-sim insertions (issue 33): anatomy, directions, scaling, errors."""

import importlib.resources

import numpy as np
import pytest

from wrist_env.anatomy import tendons as td
from wrist_env.anatomy.template import load_template
from wrist_env.errors import BuildError

MAX_ANGLE_DEG = 50.0  # APL, over the radial styloid to the 1st metacarpal's base, is the most oblique (45°)


@pytest.fixture(scope="module")
def tendons():
    return td.load_tendons()


@pytest.fixture(scope="module")
def capitate():
    return load_template().parts["capitate"].trimesh().center_mass


def _row(t, name):
    return t.names.index(name)


def test_each_tendon_loads_its_anatomical_carpal(tendons):
    expected = {"FCR": "trapezoid", "ECRL": "trapezoid", "ECRB": "capitate", "ECU": "hamate", "FCU": "hamate"}
    expected |= {"APL": "trapezium", "EPB": "trapezium", "FPL": "trapezium"}
    expected |= {
        f"{m}{k}": c
        for m in ("FDS", "FDP")
        for k, c in ((2, "trapezoid"), (3, "capitate"), (4, "hamate"), (5, "hamate"))
    }
    assert dict(zip(tendons.names, tendons.carpal)) == expected
    bones = dict(zip(tendons.names, tendons.insertion_site))
    assert bones["FCU"] == "FCU-P4_r"  # on the pisiform
    for name, site in zip(tendons.names, tendons.insertion_site):
        assert site.startswith(f"{name}-P")


def test_directions_are_unit_and_pull_proximally(tendons):
    np.testing.assert_allclose(np.linalg.norm(tendons.direction, axis=1), 1.0, atol=1e-12)
    angles = np.degrees(np.arccos(tendons.direction[:, 1]))
    assert np.all(angles < MAX_ANGLE_DEG), dict(zip(tendons.names, angles.round(1)))
    for k in range(len(tendons.names)):  # the finger flexors run straight down the carpal tunnel
        if tendons.names[k].startswith(("FDS", "FDP")):
            assert angles[k] < 5.0


def test_radial_and_ulnar_tendons(tendons, capitate):
    for name in ("FCR", "ECRL", "APL", "EPB", "FPL"):
        assert tendons.point[_row(tendons, name), 2] > capitate[2] + 5, name
    for name in ("FCU", "ECU"):
        assert tendons.point[_row(tendons, name), 2] < capitate[2] - 10, name


def test_flexors_volar_and_extensors_dorsal_where_they_cross_the_wrist(tendons):
    flexors = ["FCR", "FCU", "FPL"] + [n for n in tendons.names if n.startswith(("FDS", "FDP"))]
    for name in flexors:
        k = _row(tendons, name)
        assert tendons.point[k, 0] > 0, name
        assert td.crossing(tendons.point[k], tendons.direction[k], 0.0)[0] > 5, name
    for name in ("ECRL", "ECRB", "ECU", "EPB"):
        k = _row(tendons, name)
        # ECU's insertion on the 5th metacarpal's base lies volar of the RCS origin (the hand's arch):
        # the side is where its line crosses the radiocarpal joint (y = 0)
        assert td.crossing(tendons.point[k], tendons.direction[k], 0.0)[0] < -2, name
    for name in ("ECRL", "ECRB"):
        assert tendons.point[_row(tendons, name), 0] < 0, name


def test_points_lie_distal_of_the_radius_and_near_the_carpus(tendons):
    assert np.all(tendons.point[:, 1] < 0)
    assert np.all(np.linalg.norm(tendons.point, axis=1) < 60)


@pytest.mark.parametrize("rig", sorted(td.RIGS))
def test_scaled_tensions_sum_to_the_total(rig):
    t = td.load_tendons(rig)
    assert t.scaled(100.0).sum() == pytest.approx(100.0)
    np.testing.assert_allclose(t.scaled(37.0) / t.tension, 37.0 / t.tension.sum())


def test_erhart_rig_totals():
    assert sum(td.ERHART_2020.values()) == pytest.approx(105.0)
    assert sum(td.ERHART_2020_GROUPS.values()) == pytest.approx(70.0)
    assert td.ERHART_2020["ECRL"] + td.ERHART_2020["ECRB"] == 20.0
    assert td.ERHART_2020["APL"] + td.ERHART_2020["EPB"] == 10.0


def test_carpal_resultants_add_up_and_move_their_moments(tendons, capitate):
    loads = td.carpal_loads(tendons, 100.0, about=capitate)
    parts = [v for k, v in loads.items() if k != "all"]
    np.testing.assert_allclose(sum(v.force for v in parts), loads["all"].force, atol=1e-9)
    np.testing.assert_allclose(sum(v.moment for v in parts), loads["all"].moment, atol=1e-7)
    origin = td.carpal_loads(tendons, 100.0)
    for k, v in loads.items():  # M_O = M_c + (c - O) × F
        np.testing.assert_allclose(origin[k].moment, v.moment + np.cross(capitate, v.force), atol=1e-7)
        # the point lies on the resultant's central axis: the moment about it is along F
        M = v.moment + np.cross(v.about - v.point, v.force)
        np.testing.assert_allclose(
            np.cross(M, v.force), 0.0, atol=1e-9 * np.linalg.norm(v.moment) * np.linalg.norm(v.force)
        )
    assert loads["all"].force[1] > 90.0  # the rig compresses the wrist


def test_tensions_are_read_only(tendons):
    with pytest.raises(ValueError):
        tendons.tension[0] = 0.0


def test_bad_xml_path_names_the_file(tmp_path):
    bad = tmp_path / "no_such_chain.xml"
    with pytest.raises(BuildError, match="no_such_chain.xml"):
        td.load_tendons(chain_xml=bad)
    with pytest.raises(BuildError, match="no_such_tendon.xml"):
        td.load_tendons(tendon_xml=tmp_path / "no_such_tendon.xml")


def test_missing_site_names_the_file_and_the_site(tmp_path):
    text = (importlib.resources.files("myo_sim") / td.TENDON_XML).read_text()
    broken = tmp_path / "tendon.xml"
    broken.write_text(text.replace('site="FCR-P3_r"', 'site="FCR-P9_r"'))
    with pytest.raises(BuildError, match=r"myoarm_r_chain\.xml.*FCR-P9_r"):
        td.load_tendons(tendon_xml=broken)


def test_unknown_tendon_is_refused():
    with pytest.raises(BuildError, match="EDC2"):
        td.load_tendons({"EDC2": 5.0})


def test_resultant_direction_is_the_rigs_resultant_as_a_unit_vector(tendons):
    """The loaded driver's tendon direction: the "all" resultant normalized, within 15° of the radius'
    axis (the tendons run along the forearm), and an unknown rig is refused by name."""
    d = td.resultant_direction("erhart2020")
    force = td.carpal_loads(tendons, 100.0)["all"].force
    assert np.allclose(d, force / np.linalg.norm(force)) and np.isclose(np.linalg.norm(d), 1.0)
    assert np.degrees(np.arccos(d[1])) < 15.0, d
    with pytest.raises(ValueError, match="no_such_rig"):
        td.resultant_direction("no_such_rig")
