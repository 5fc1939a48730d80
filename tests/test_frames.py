"""Frames: 4×4 ↔ 6 DOF, Cardan Z-X-Y conventions and signs, error transforms, RMSE, input validation."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from wrist_env.errors import InputError
from wrist_env.frames import (
    DOF_NAMES,
    cardan_angles,
    cardan_rotation,
    dof_to_pose,
    error_dof,
    error_transform,
    invert,
    pose_to_dof,
    rmse,
)
from wrist_env.pose_checks import validate_poses


def pose(rotation=np.eye(3), translation=(0.0, 0.0, 0.0)) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = rotation
    out[:3, 3] = translation
    return out


def about(point, rotation) -> np.ndarray:
    """Rotation about a point (mm): Trans(p)·R·Trans(−p)."""
    point = np.asarray(point, float)
    return pose(rotation, point - rotation @ point)


def rz(deg):
    return Rotation.from_euler("z", deg, degrees=True).as_matrix()


def random_poses(shape, seed=0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n = int(np.prod(shape))
    angles = np.c_[rng.uniform(-170, 170, n), rng.uniform(-80, 80, n), rng.uniform(-170, 170, n)]
    out = np.tile(np.eye(4), (n, 1, 1))
    out[:, :3, :3] = Rotation.from_euler("ZXY", angles, degrees=True).as_matrix()
    out[:, :3, 3] = rng.uniform(-30, 30, (n, 3))
    return out.reshape(*shape, 4, 4)


def test_dof_names_follow_table_3():
    assert DOF_NAMES == ("Vol/Dor", "Pro/Dis", "Rad/Uln", "Flex/Ext", "UlnD/RadD", "Pro/Sup")


@pytest.mark.parametrize("reference_point", [None, (3.0, -12.0, 8.0)])
def test_round_trip_pose_dof_pose(reference_point):
    poses = random_poses((4, 7))
    dof = pose_to_dof(poses, reference_point)
    assert dof.shape == (4, 7, 6)
    np.testing.assert_allclose(dof_to_pose(dof, reference_point), poses, atol=1e-10)


def test_round_trip_dof_pose_dof():
    rng = np.random.default_rng(1)
    dof = np.c_[
        rng.uniform(-20, 20, (50, 3)), rng.uniform(-170, 170, 50), rng.uniform(-85, 85, 50), rng.uniform(-170, 170, 50)
    ]
    c = np.array([1.0, -15.0, 4.0])
    np.testing.assert_allclose(pose_to_dof(dof_to_pose(dof, c), c), dof, atol=1e-9)


def test_cardan_is_intrinsic_zxy_like_scipy():
    angles = np.array([25.0, -12.0, 7.0])  # flexion, ulnar deviation, pronation
    expected = Rotation.from_euler("ZXY", angles, degrees=True).as_matrix()
    rx = Rotation.from_euler("x", angles[1], degrees=True).as_matrix()
    ry = Rotation.from_euler("y", angles[2], degrees=True).as_matrix()
    by_hand = rz(angles[0]) @ rx @ ry  # intrinsic z, x', y'': post-multiplied
    np.testing.assert_allclose(cardan_rotation(angles), expected, atol=1e-12)
    np.testing.assert_allclose(cardan_rotation(angles), by_hand, atol=1e-12)
    np.testing.assert_allclose(cardan_angles(by_hand), angles, atol=1e-10)
    extrinsic = Rotation.from_euler("zxy", angles, degrees=True).as_matrix()
    assert np.abs(cardan_angles(extrinsic) - angles).max() > 0.5  # the other convention differs


def test_signs_of_rotations():
    flexion = pose_to_dof(pose(rz(10.0)))
    np.testing.assert_allclose(flexion, [0, 0, 0, 10, 0, 0], atol=1e-12)
    # flexion (+z) carries a distal point volar (+x)
    assert (rz(10.0) @ [0, -1, 0])[0] > 0
    ulnar = Rotation.from_euler("x", 10.0, degrees=True).as_matrix()
    np.testing.assert_allclose(pose_to_dof(pose(ulnar)), [0, 0, 0, 0, 10, 0], atol=1e-12)
    assert (ulnar @ [0, -1, 0])[2] < 0  # ulnar deviation carries a distal point ulnar (−z)
    pronation = Rotation.from_euler("y", 10.0, degrees=True).as_matrix()
    np.testing.assert_allclose(pose_to_dof(pose(pronation)), [0, 0, 0, 0, 0, 10], atol=1e-12)


def test_translations_and_reference_point():
    np.testing.assert_allclose(pose_to_dof(pose(translation=(1, 2, -3))), [1, 2, -3, 0, 0, 0], atol=1e-12)
    # 90° flexion about the origin moves the point (0, −10, 0) to (10, 0, 0): displacement (10, 10, 0)
    np.testing.assert_allclose(pose_to_dof(pose(rz(90.0)), (0, -10, 0)), [10, 10, 0, 90, 0, 0], atol=1e-12)
    # a rotation about the reference point itself has no translation
    c = (4.0, -20.0, 6.0)
    np.testing.assert_allclose(pose_to_dof(about(c, rz(30.0)), c), [0, 0, 0, 30, 0, 0], atol=1e-12)
    np.testing.assert_allclose(pose_to_dof(np.eye(4), c), np.zeros(6), atol=1e-12)


def test_per_bone_reference_points_broadcast():
    poses = random_poses((2, 5), seed=3)
    points = np.array([[1.0, -10.0, 9.0], [0.0, -11.0, -2.0]])
    dof = pose_to_dof(poses, points[:, None, :])
    for b in range(2):
        for f in range(5):
            np.testing.assert_allclose(dof[b, f], pose_to_dof(poses[b, f], points[b]), atol=1e-12)


@pytest.mark.parametrize("expressed_in", ["bone", "rcs"])
def test_error_of_identical_poses_is_zero(expressed_in):
    poses = random_poses((2, 6), seed=4)
    np.testing.assert_allclose(
        error_transform(poses, poses, expressed_in=expressed_in), np.tile(np.eye(4), (2, 6, 1, 1)), atol=1e-12
    )
    np.testing.assert_allclose(error_dof(poses, poses, (2.0, -9.0, 5.0), expressed_in=expressed_in), 0.0, atol=1e-10)
    np.testing.assert_allclose(rmse(poses, poses, expressed_in=expressed_in), 0.0, atol=1e-10)


def test_error_transform_definitions():
    experiment = random_poses((5,), seed=5)
    model = random_poses((5,), seed=6)
    np.testing.assert_allclose(error_transform(model, experiment), invert(experiment) @ model, atol=1e-12)
    np.testing.assert_allclose(
        error_transform(model, experiment, expressed_in="rcs"), model @ np.linalg.inv(experiment), atol=1e-10
    )
    np.testing.assert_allclose(invert(experiment) @ experiment, np.tile(np.eye(4), (5, 1, 1)), atol=1e-12)


def test_bone_and_rcs_conventions_differ_as_documented():
    experiment = pose(rz(90.0))
    model = pose(translation=(1.0, 0.0, 0.0)) @ experiment  # 1 mm volar in the RCS
    np.testing.assert_allclose(error_dof(model, experiment, expressed_in="rcs"), [1, 0, 0, 0, 0, 0], atol=1e-12)
    # in the experimental bone's axes (turned 90° about z) RCS volar is the bone's −y
    np.testing.assert_allclose(error_dof(model, experiment, expressed_in="bone"), [0, -1, 0, 0, 0, 0], atol=1e-12)


def test_rotation_error_about_the_centroid():
    c = np.array([3.0, -14.0, 7.0])
    experiment = random_poses((8,), seed=7)
    model = experiment @ about(c, rz(3.0))  # 3° more flexion about the bone's own centroid and axes
    np.testing.assert_allclose(error_dof(model, experiment, c), np.tile([0, 0, 0, 3, 0, 0], (8, 1)), atol=1e-10)
    np.testing.assert_allclose(rmse(model, experiment, c), [0, 0, 0, 3, 0, 0], atol=1e-10)
    # tracked at the RCS origin instead, the same error shows a lever-arm translation
    assert np.abs(error_dof(model, experiment)[:, :3]).max() > 0.1
    # rcs: a rotation about the experimental centroid in RCS axes
    centroids = experiment[:, :3, :3] @ c + experiment[:, :3, 3]
    model_rcs = np.array([about(p, rz(-2.0)) for p in centroids]) @ experiment
    np.testing.assert_allclose(rmse(model_rcs, experiment, c, expressed_in="rcs"), [0, 0, 0, 2, 0, 0], atol=1e-10)


def test_rmse_of_known_offsets():
    experiment = np.tile(pose(rz(0.0)), (4, 1, 1))
    experiment[:, :3, :3] = Rotation.from_euler("z", np.array([-20.0, -5, 5, 20])[:, None], degrees=True).as_matrix()
    offsets = np.array([[0.5, -1.0, 2.0]] * 4)
    model = np.array([pose(translation=o) for o in offsets]) @ experiment
    np.testing.assert_allclose(rmse(model, experiment, expressed_in="rcs"), [0.5, 1.0, 2.0, 0, 0, 0], atol=1e-12)
    # alternating errors 1 and 3 mm proximal: RMSE = sqrt((1 + 9) / 2) = sqrt(5)
    model = np.array([pose(translation=(0, e, 0)) for e in (1, 3, 1, 3)]) @ experiment
    np.testing.assert_allclose(rmse(model, experiment, expressed_in="rcs")[1], np.sqrt(5.0), rtol=1e-12)


def test_vectorized_over_bones_and_frames():
    experiment = random_poses((2, 5), seed=8)
    model = random_poses((2, 5), seed=9)
    points = np.array([[1.0, -10.0, 9.0], [0.0, -11.0, -2.0]])[:, None, :]
    batch = rmse(model, experiment, points)
    assert batch.shape == (2, 6)
    for b in range(2):
        np.testing.assert_allclose(batch[b], rmse(model[b], experiment[b], points[b, 0]), atol=1e-12)


def test_bad_poses_raise_input_errors():
    good = np.tile(np.eye(4), (3, 1, 1))
    assert issubclass(InputError, ValueError)
    scaled = good.copy()
    scaled[1, :3, :3] *= 1.01
    with pytest.raises(InputError, match=r"orthonormal.*entry \(1,\).*0\.0201"):
        validate_poses(scaled)
    nan = good.copy()
    nan[2, 0, 3] = np.nan
    with pytest.raises(InputError, match=r"finite.*entry \(2,\).*m03=nan"):
        pose_to_dof(nan)
    with pytest.raises(InputError, match=r"shape \(\.\.\., 4, 4\).*\(3, 3\)"):
        pose_to_dof(np.eye(3))
    mirrored = good.copy()
    mirrored[0] = np.diag([1.0, 1.0, -1.0, 1.0])
    with pytest.raises(InputError, match="proper.*det = -1"):
        validate_poses(mirrored)
    bottom = good.copy()
    bottom[0, 3, 0] = 0.5
    with pytest.raises(InputError, match="bottom row"):
        validate_poses(bottom)
    with pytest.raises(InputError, match="experimental poses.*finite"):
        error_dof(good, nan)
    with pytest.raises(InputError, match=r"same shape.*\(3, 4, 4\).*\(2, 4, 4\)"):
        error_transform(good, good[:2])
    with pytest.raises(InputError, match=r"reference_point.*\(2,\)"):
        pose_to_dof(good, (1.0, 2.0))
    with pytest.raises(InputError, match="reference_point.*finite"):
        pose_to_dof(good, (1.0, np.nan, 2.0))
    with pytest.raises(InputError, match="expressed_in"):
        error_transform(good, good, expressed_in="world")
    with pytest.raises(InputError, match=r"dof.*\(5,\)"):
        dof_to_pose(np.zeros(5))
    with pytest.raises(InputError, match=r"Flex/Ext.*inf"):
        dof_to_pose([0, 0, 0, np.inf, 0, 0])


def test_error_of_poses_at_the_orthonormality_tolerance_is_accepted():
    # each pose is within tolerance (max |RᵀR − I| ≈ 8e-5); their error transform is not (≈ 1.6e-4)
    near = np.tile(np.eye(4), (3, 1, 1))
    near[:, :3, :3] *= 1.00004
    validate_poses(near)
    validate_poses(invert(near))
    with pytest.raises(InputError, match="orthonormal"):
        validate_poses(near @ near)
    np.testing.assert_allclose(error_dof(near, invert(near)), 0.0, atol=1e-6)
    np.testing.assert_allclose(rmse(near, invert(near)), 0.0, atol=1e-6)
