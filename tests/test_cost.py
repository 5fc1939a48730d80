"""Kinematic cost: zero for identical kinematics, hand-computed terms, 75th percentile, weights, floor, failure penalty."""

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from wrist_env.cost import FAILED_COST, RANGE_FLOOR, CostWeights, kinematic_cost
from wrist_env.errors import InputError
from wrist_env.frames import DOF_NAMES, rmse

CENTROIDS = np.array([[3.0, -12.0, 9.0], [0.0, -11.0, -3.0]])  # scaphoid, lunate (mm, RCS)
FLEX = 3
VOL = 0


def about(point, axis: str, deg: float, translation=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Rotation by deg about an RCS axis through point (mm), then a translation (mm)."""
    rot = Rotation.from_euler(axis, deg, degrees=True).as_matrix()
    out = np.eye(4)
    out[:3, :3] = rot
    out[:3, 3] = point - rot @ point + np.asarray(translation, float)
    return out


def experiment(flexion=(-20.0, -5.0, 5.0, 20.0), volar=(0.0, 1.0, 3.0, 4.0)) -> np.ndarray:
    """(2, n_frames, 4, 4): both bones flex about their centroids (range 40°) and glide volar (range 4 mm)."""
    return np.array([[about(c, "z", a, (v, 0.0, 0.0)) for a, v in zip(flexion, volar)] for c in CENTROIDS])


def with_error(poses, bone: int, axis: str, deg_per_frame, translation=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Model poses: one bone turned by deg (per frame) about its own centroid and axes, plus a translation in its axes."""
    out = poses.copy()
    for f, deg in enumerate(np.broadcast_to(deg_per_frame, poses.shape[1])):
        out[bone, f] = poses[bone, f] @ about(CENTROIDS[bone], axis, deg, translation)
    return out


def test_identical_kinematics_cost_zero():
    exp = experiment()
    report = kinematic_cost(exp, exp, reference_points=CENTROIDS)
    assert report.total == pytest.approx(0.0, abs=1e-12)
    assert not report.failed
    np.testing.assert_allclose(report.terms, 0.0, atol=1e-12)
    np.testing.assert_allclose(report.rmse, 0.0, atol=1e-10)
    np.testing.assert_allclose(report.experimental_range[:, FLEX], 40.0, atol=1e-10)
    np.testing.assert_allclose(report.experimental_range[:, VOL], 4.0, atol=1e-10)


def test_constant_flexion_error_hand_computed():
    exp = experiment()
    model = with_error(exp, 0, "z", 1.0)  # scaphoid: 1° more flexion at every frame
    report = kinematic_cost(model, exp, reference_points=CENTROIDS)
    expected = np.zeros((2, 6))
    expected[0, FLEX] = 1.0 * 1.0 / 40.0
    np.testing.assert_allclose(report.terms, expected, atol=1e-10)
    assert report.total == pytest.approx(0.025, abs=1e-10)
    assert report.error_p75[0, FLEX] == pytest.approx(1.0, abs=1e-10)
    assert report.rmse[0, FLEX] == pytest.approx(1.0, abs=1e-10)


def test_translation_and_rotation_terms_add_up():
    exp = experiment()
    model = with_error(exp, 1, "z", 2.0, translation=(0.5, 0.0, 0.0))  # lunate: 2° flexion, 0.5 mm volar
    report = kinematic_cost(model, exp, reference_points={"scaphoid": CENTROIDS[0], "lunate": CENTROIDS[1]})
    assert report.terms[1, FLEX] == pytest.approx(2.0 / 40.0, abs=1e-10)
    assert report.terms[1, VOL] == pytest.approx(0.5 / 4.0, abs=1e-10)
    assert report.total == pytest.approx(0.05 + 0.125, abs=1e-10)
    assert report.total == pytest.approx(report.terms.sum(), rel=1e-12)


def test_percentile_is_the_75th_of_absolute_errors_with_linear_interpolation():
    exp = experiment()
    model = with_error(exp, 0, "z", [-1.0, 2.0, -3.0, 10.0])
    report = kinematic_cost(model, exp, reference_points=CENTROIDS)
    # |errors| sorted 1, 2, 3, 10: position 0.75·3 = 2.25 → 3 + 0.25·(10 − 3) = 4.75
    assert report.error_p75[0, FLEX] == pytest.approx(4.75, abs=1e-9)
    assert report.terms[0, FLEX] == pytest.approx(4.75 / 40.0, abs=1e-9)
    assert report.rmse[0, FLEX] == pytest.approx(np.sqrt((1 + 4 + 9 + 100) / 4), abs=1e-9)


def test_weights_override():
    exp = experiment()
    model = with_error(exp, 0, "z", 1.0, translation=(0.5, 0.0, 0.0))
    base = kinematic_cost(model, exp, reference_points=CENTROIDS)
    heavy = kinematic_cost(model, exp, reference_points=CENTROIDS, weights=CostWeights(flex_ext=3.0, vol_dor=0.0))
    assert heavy.terms[0, FLEX] == pytest.approx(3 * base.terms[0, FLEX], rel=1e-12)
    assert heavy.terms[0, VOL] == 0.0
    assert heavy.total == pytest.approx(3 * 0.025, abs=1e-10)
    by_name = kinematic_cost(model, exp, reference_points=CENTROIDS, weights={"Flex/Ext": 3.0, "vol_dor": 0.0})
    assert by_name.total == pytest.approx(heavy.total, rel=1e-12)
    assert heavy.to_dict()["weights"]["Flex/Ext"] == 3.0


def test_bad_weights():
    with pytest.raises(InputError, match="flex_ext.*-1"):
        CostWeights(flex_ext=-1.0)
    with pytest.raises(InputError, match="all be 0"):
        CostWeights(*[0.0] * 6)
    with pytest.raises(InputError, match="unknown DOF.*Flexion"):
        CostWeights.from_mapping({"Flexion": 1.0})
    with pytest.raises(InputError, match="weights must be"):
        kinematic_cost(experiment(), experiment(), weights=[1.0] * 6)


def test_zero_range_uses_the_floor():
    exp = experiment()  # no radial–ulnar translation at all
    model = with_error(exp, 0, "z", 0.0, translation=(0.0, 0.0, 0.3))
    report = kinematic_cost(model, exp, reference_points=CENTROIDS)
    assert report.experimental_range[0, 2] == pytest.approx(0.0, abs=1e-12)
    assert report.normalizer[0, 2] == RANGE_FLOOR[2] == 1.0
    assert report.terms[0, 2] == pytest.approx(0.3, abs=1e-10)
    assert np.isfinite(report.total)
    finer = kinematic_cost(model, exp, reference_points=CENTROIDS, range_floor=(0.5,) * 6)
    assert finer.terms[0, 2] == pytest.approx(0.6, abs=1e-10)
    with pytest.raises(InputError, match="range_floor"):
        kinematic_cost(model, exp, range_floor=(0.0,) * 6)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_failed_simulation_costs_the_penalty(bad):
    exp = experiment()
    model = exp.copy()
    model[1, 2, 0, 3] = bad
    report = kinematic_cost(model, exp, reference_points=CENTROIDS)
    assert report.failed
    assert report.total == FAILED_COST == 1e3
    assert np.isnan(report.terms).all() and np.isnan(report.rmse).all()
    as_json = json.loads(json.dumps(report.to_dict(), allow_nan=False))
    assert as_json["total"] == 1e3 and as_json["failed"] is True
    assert as_json["terms"]["lunate"]["Flex/Ext"] is None
    assert as_json["experimental_range"]["scaphoid"]["Flex/Ext"] == pytest.approx(40.0)


def test_bad_experiment_raises():
    exp = experiment()
    nan = exp.copy()
    nan[0, 1, 1, 1] = np.nan
    with pytest.raises(InputError, match="experimental poses.*finite.*m11=nan"):
        kinematic_cost(exp, nan)
    with pytest.raises(InputError, match=r"n_frames >= 2"):
        kinematic_cost(exp[:, :1], exp[:, :1])
    with pytest.raises(InputError, match=r"shape \(2, n_frames, 4, 4\)"):
        kinematic_cost(exp[:1], exp[:1])
    with pytest.raises(InputError, match=r"model poses.*\(2, 4, 4, 4\).*\(2, 3, 4, 4\)"):
        kinematic_cost(exp[:, :3], exp)
    skewed = exp.copy()
    skewed[0, 0, :3, :3] *= 1.1
    with pytest.raises(InputError, match="model poses.*orthonormal"):
        kinematic_cost(skewed, exp)
    with pytest.raises(InputError, match=r"reference_points.*\(3,\)"):
        kinematic_cost(exp, exp, reference_points=[1.0, 2.0, 3.0])


def test_mapping_input_matches_array_input():
    exp = experiment()
    model = with_error(exp, 0, "x", 1.5)
    as_array = kinematic_cost(model, exp, reference_points=CENTROIDS)
    capitate = np.tile(np.eye(4), (4, 1, 1))
    as_mapping = kinematic_cost(
        {"lunate": model[1], "scaphoid": model[0], "capitate": capitate},
        {"scaphoid": exp[0], "lunate": exp[1]},
        reference_points=CENTROIDS,
    )
    assert as_mapping.total == pytest.approx(as_array.total, rel=1e-12)
    assert as_array.terms[0, 4] == pytest.approx(1.5 / RANGE_FLOOR[4], abs=1e-9)  # deviation does not move: floored
    with pytest.raises(InputError, match=r"\['lunate'\] are missing"):
        kinematic_cost({"scaphoid": model[0]}, exp)


def test_reference_point_matters_for_translations():
    exp = experiment()
    model = with_error(exp, 0, "z", 2.0)  # a pure rotation about the scaphoid centroid
    at_centroid = kinematic_cost(model, exp, reference_points=CENTROIDS)
    at_origin = kinematic_cost(model, exp)
    np.testing.assert_allclose(at_centroid.error_p75[0, :3], 0.0, atol=1e-10)
    # tracked at the RCS origin the 2° turn shows a lever-arm shift of |c|·2·sin(1°) ≈ 0.55 mm
    shift = np.linalg.norm(CENTROIDS[0][:2]) * 2 * np.sin(np.radians(1.0))
    assert np.linalg.norm(at_origin.error_p75[0, :2]) == pytest.approx(shift, rel=1e-6)
    assert at_origin.total > at_centroid.total


def test_report_rmse_and_dict():
    exp = experiment()
    model = with_error(exp, 1, "y", [1.0, -2.0, 0.5, 3.0], translation=(0.2, -0.1, 0.4))
    report = kinematic_cost(model, exp, reference_points=CENTROIDS)
    np.testing.assert_allclose(report.rmse, rmse(model, exp, CENTROIDS[:, None, :]), atol=1e-12)
    data = json.loads(json.dumps(report.to_dict(), allow_nan=False))
    assert set(data["terms"]) == {"scaphoid", "lunate"}
    assert tuple(data["rmse"]["lunate"]) == DOF_NAMES
    assert data["units"]["Pro/Sup"] == "deg" and data["units"]["Vol/Dor"] == "mm"
    assert sum(v for bone in data["terms"].values() for v in bone.values()) == pytest.approx(data["total"], rel=1e-12)
    assert data["rmse"]["lunate"]["Pro/Sup"] == pytest.approx(np.sqrt((1 + 4 + 0.25 + 9) / 4), abs=1e-9)
    with pytest.raises(ValueError):
        report.terms[0, 0] = 1.0  # read-only
