"""Trials: CSV round trip, mirroring, and one test per validation rule."""

import re

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

from wrist_env.errors import TrialError
from wrist_env.trial import (
    COLUMNS,
    MATRIX_COLUMNS,
    MIRROR,
    Trial,
    mirror_trial,
    read_trial_csv,
    validate_transforms,
    write_trial_csv,
)

BONES = ("radius", "ulna", "scaphoid", "lunate", "capitate")
# rotation centres (mm, RCS) and share of the hand's motion of each bone
CENTRES = {
    "radius": (0, 0, 0),
    "ulna": (0, 0, -20),
    "scaphoid": (2, -10, 10),
    "lunate": (0, -10, -2),
    "capitate": (0, -28, 3),
}
SHARE = {"radius": 0.0, "ulna": 0.0, "scaphoid": 0.8, "lunate": 0.5, "capitate": 1.0}


def flexion_transforms(n_frames: int = 15, peak_deg: float = 30.0) -> np.ndarray:
    """Array of shape (5, n_frames, 4, 4): each bone rotates about its centre (flexion about z, some deviation about x)."""
    angles = peak_deg * np.sin(np.linspace(0, 2 * np.pi, n_frames))
    out = np.tile(np.eye(4), (len(BONES), n_frames, 1, 1))
    for b, bone in enumerate(BONES):
        rot = Rotation.from_euler("ZX", np.c_[angles, 0.2 * angles] * SHARE[bone], degrees=True).as_matrix()
        c = np.array(CENTRES[bone], float)
        out[b, :, :3, :3] = rot
        out[b, :, :3, 3] = c - rot @ c
    return out


def make_trial(n_frames: int = 15, role: str = "calibrate") -> Trial:
    return Trial("unresisted", role, BONES, flexion_transforms(n_frames))


@pytest.fixture
def csv_path(tmp_path):
    path = tmp_path / "unresisted.csv"
    write_trial_csv(make_trial(), path)
    return path


def edit_csv(path, edit) -> None:
    """Rewrite the CSV at `path` with `edit(table) -> table` applied."""
    table = pd.read_csv(path)
    edit(table).to_csv(path, index=False, float_format="%.17g")


def raises(path, value: str):
    """pytest.raises(TrialError) whose message names the file and the value."""
    return pytest.raises(TrialError, match=f"(?s){re.escape(str(path))}.*{value}")


def test_round_trip_is_exact(csv_path):
    trial = make_trial()
    back = read_trial_csv(csv_path, "unresisted", "calibrate")
    assert (back.name, back.role, back.bones, back.n_frames) == ("unresisted", "calibrate", BONES, 15)
    assert back.transforms.dtype == np.float64
    np.testing.assert_array_equal(back.transforms, trial.transforms)


def test_csv_layout(csv_path):
    lines = csv_path.read_text().splitlines()
    assert lines[0] == ",".join(COLUMNS)
    assert len(lines) == 1 + 5 * 15
    assert lines[1].startswith("0,radius,1,0,0,0,") and lines[5].startswith("0,capitate,")
    assert lines[6].startswith("1,radius,")


def test_rows_in_any_order_read_the_same(csv_path):
    edit_csv(csv_path, lambda t: t.sample(frac=1.0, random_state=np.random.default_rng(0)))
    np.testing.assert_array_equal(read_trial_csv(csv_path, "u", "other").transforms, make_trial().transforms)


def test_optional_bones_may_be_absent(csv_path):
    edit_csv(csv_path, lambda t: t[t.bone != "ulna"])
    trial = read_trial_csv(csv_path, "u", "validate")
    assert trial.bones == ("radius", "scaphoid", "lunate", "capitate")
    np.testing.assert_array_equal(trial.pose("capitate"), make_trial().pose("capitate"))


def test_pose_and_read_only():
    trial = make_trial(n_frames=7)
    assert trial.n_frames == 7
    assert trial.pose("lunate").shape == (7, 4, 4)
    np.testing.assert_allclose(trial.pose("radius"), np.tile(np.eye(4), (7, 1, 1)))
    with pytest.raises(ValueError):
        trial.transforms[0, 0, 0, 0] = 2.0
    with pytest.raises(TrialError, match="no bone 'hamate'"):
        trial.pose("hamate")


def test_a_trials_load_is_one_finite_nonnegative_value_per_frame():
    """A trial may carry its total tendon load per frame (N); a wrong length, a NaN or a pull is refused,
    naming the trial; a mirrored trial keeps it."""
    trial = make_trial(n_frames=7)
    assert trial.load_n is None
    loaded = Trial(trial.name, trial.role, trial.bones, trial.transforms, np.linspace(10.0, 40.0, 7))
    assert loaded.load_n[-1] == 40.0 and not loaded.load_n.flags.writeable
    np.testing.assert_array_equal(mirror_trial(loaded).load_n, loaded.load_n)
    for bad in (np.ones(6), np.r_[np.ones(6), np.nan], np.r_[np.ones(6), -1.0]):
        with pytest.raises(TrialError, match=f"trial {trial.name!r}: load_n"):
            Trial(trial.name, trial.role, trial.bones, trial.transforms, bad)


def test_mirror_trial_moves_mirrored_points_to_mirrored_poses():
    trial = make_trial()
    mirrored = mirror_trial(trial)
    np.testing.assert_allclose(np.linalg.det(mirrored.transforms[..., :3, :3]), 1.0, atol=1e-12)
    point = np.array([3.0, -12.0, 7.0, 1.0])
    moved = trial.pose("scaphoid") @ point
    np.testing.assert_allclose(mirrored.pose("scaphoid") @ (MIRROR @ point), moved @ MIRROR, atol=1e-12)
    np.testing.assert_allclose(mirror_trial(mirrored).transforms, trial.transforms, atol=1e-15)


def test_validate_transforms_accepts_single_pose_and_returns_float64():
    out = validate_transforms(np.eye(4, dtype=np.float32), "pose")
    assert out.dtype == np.float64 and out.shape == (4, 4)


# --- one test per error ---------------------------------------------------------------


def test_nan(csv_path):
    edit_csv(csv_path, lambda t: t.assign(m01=np.where((t.frame == 3) & (t.bone == "lunate"), np.nan, t.m01)))
    with raises(csv_path, "finite.*bone 'lunate' frame 3 has m01=nan"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_a_translation_shifted_by_a_million_mm_is_refused(csv_path):
    shifted = lambda t: t.assign(m13=np.where((t.frame == 4) & (t.bone == "lunate"), t.m13 + 1e6, t.m13))  # noqa: E731
    edit_csv(csv_path, shifted)
    with raises(csv_path, r"within 100 mm of the neutral pose, but bone 'lunate' frame 4 is 1e\+06 mm away"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_inf(csv_path):
    edit_csv(csv_path, lambda t: t.assign(m13=np.where((t.frame == 9) & (t.bone == "capitate"), np.inf, t.m13)))
    with raises(csv_path, "finite.*bone 'capitate' frame 9 has m13=inf"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_non_orthonormal_rotation(csv_path):
    row = lambda t: (t.frame == 4) & (t.bone == "scaphoid")  # noqa: E731
    edit_csv(csv_path, lambda t: t.assign(m00=np.where(row(t), t.m00 * 1.01, t.m00)))
    m00 = make_trial().pose("scaphoid")[4, 0, 0]
    deviation = (1.01**2 - 1) * m00**2  # (RᵀR − I)[0, 0] with column 0 scaled in its first entry
    with raises(csv_path, rf"orthonormal.*bone 'scaphoid' frame 4 has max \|RᵀR − I\| = {deviation:.3g}"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_reflection(csv_path):
    row = lambda t: (t.frame == 2) & (t.bone == "lunate")  # noqa: E731
    edit_csv(csv_path, lambda t: t.assign(**{c: np.where(row(t), -t[c], t[c]) for c in ("m02", "m12", "m22")}))
    with raises(csv_path, "det = \\+1.*bone 'lunate' frame 2 has det = -1"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_bones_with_different_frames(csv_path):
    edit_csv(csv_path, lambda t: t[~((t.bone == "lunate") & (t.frame == 14))])
    with raises(csv_path, r"bone 'lunate' lacks frames \[14\]"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_frames_with_a_gap(csv_path):
    edit_csv(csv_path, lambda t: t[t.frame != 7])
    with raises(csv_path, r"without gaps.*0\.\.14 with \[7\] missing"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_frames_not_from_zero(csv_path):
    edit_csv(csv_path, lambda t: t.assign(frame=t.frame + 1))
    with raises(csv_path, r"without gaps.*run 1\.\.15"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_fewer_than_two_frames(csv_path):
    edit_csv(csv_path, lambda t: t[t.frame == 0])
    with raises(csv_path, "at least 2 frames, but got 1"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_frame_count_differs_from_required(csv_path):
    with raises(csv_path, "must have n_frames=12 frames, but has 15"):
        read_trial_csv(csv_path, "u", "calibrate", n_frames=12)


def test_missing_required_bone(csv_path):
    edit_csv(csv_path, lambda t: t[t.bone != "capitate"])
    with raises(csv_path, r"\['capitate'\] are missing"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_unknown_bone(csv_path):
    edit_csv(csv_path, lambda t: t.assign(bone=t.bone.replace("lunate", "Lunate")))
    with raises(csv_path, "lower case.*line 5 has 'Lunate'"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_missing_column(csv_path):
    edit_csv(csv_path, lambda t: t.drop(columns="m23"))
    with raises(csv_path, r"missing=\['m23'\]"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_extra_column(csv_path):
    edit_csv(csv_path, lambda t: t.assign(m30=0.0))
    with raises(csv_path, r"extra=\['m30'\]"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_non_numeric_value(csv_path):
    edit_csv(csv_path, lambda t: t.astype({"m12": object}).assign(m12=lambda s: s.m12.where(s.index != 20, "0.5x")))
    with raises(csv_path, "column m12 must hold numbers, but line 22 has '0.5x'"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_duplicate_row(csv_path):
    edit_csv(csv_path, lambda t: pd.concat([t, t.iloc[[7]]]))
    with raises(csv_path, "line 77 repeats frame 1 bone 'scaphoid'"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_translations_in_metres(csv_path):
    edit_csv(csv_path, lambda t: t.assign(**{c: t[c] / 1000 for c in ("m03", "m13", "m23")}))
    largest = np.abs(make_trial().transforms[..., :3, 3]).max() / 1000
    with raises(csv_path, rf"translations look like metres; use mm \(largest \|t\| = {largest:.3g}"):
        read_trial_csv(csv_path, "u", "calibrate")


def test_metres_rule_needs_rotation_over_five_degrees():
    # rotations about the origin have zero translation: flagged only once they span > 5°
    transforms = np.tile(np.eye(4), (len(BONES), 2, 1, 1))
    transforms[2, 1, :3, :3] = Rotation.from_rotvec([0, 0, 4.9], degrees=True).as_matrix()
    Trial("small", "other", BONES, transforms)
    transforms[2, 1, :3, :3] = Rotation.from_rotvec([0, 0, 5.1], degrees=True).as_matrix()
    with pytest.raises(TrialError, match="trial 'small': translations look like metres.*vary by 5.1°"):
        Trial("small", "other", BONES, transforms)


def test_missing_file(tmp_path):
    with raises(tmp_path / "absent.csv", "does not exist"):
        read_trial_csv(tmp_path / "absent.csv", "u", "calibrate")


def test_bad_role():
    with pytest.raises(TrialError, match="role must be one of.*'calibration'"):
        make_trial(role="calibration")


def test_bottom_row():
    transforms = flexion_transforms()
    transforms[2, 5, 3, 0] = 0.1
    with pytest.raises(
        TrialError, match=r"my array: the bottom row.*bone 'scaphoid' frame 5 has \[0.1, 0.0, 0.0, 1.0\]"
    ):
        validate_transforms(transforms, "my array", BONES)


def test_wrong_shape():
    with pytest.raises(TrialError, match=r"my array: .*shape \(\.\.\., 4, 4\), but got \(5, 3, 3\)"):
        validate_transforms(np.zeros((5, 3, 3)), "my array")


def test_non_integer_frame(csv_path):
    edit_csv(csv_path, lambda t: t.assign(frame=t.frame.astype(float).where(t.index != 11, 2.5)))
    with raises(csv_path, "column frame must hold integers, but line 13 has '2.5'"):
        read_trial_csv(csv_path, "u", "calibrate")


# --- issue 53: the radius and ulna rows, the frame limit ---------------------------------


def _turn_row(bone: str, frame: int, deg: float = 0.0, shift_mm: float = 0.0):
    """An edit of one bone's row on one frame: a turn about y by `deg` after it, and a shift along x."""

    def edit(t):
        row = (t.frame == frame) & (t.bone == bone)
        turn = Rotation.from_euler("y", deg, degrees=True).as_matrix()
        matrix = t.loc[row, list(MATRIX_COLUMNS)].to_numpy().reshape(3, 4)
        moved = np.c_[turn @ matrix[:, :3], turn @ matrix[:, 3] + [shift_mm, 0.0, 0.0]]
        t.loc[row, list(MATRIX_COLUMNS)] = moved.ravel()
        return t

    return edit


@pytest.mark.parametrize(
    "bone, deg, shift_mm, value",
    [
        (
            "radius",
            0.0,
            1.5,
            r"radius must stay at the identity .*within 1 mm and 2°, but frame 6 has it 1.5 mm and 0°",
        ),
        ("radius", 3.0, 0.0, r"radius must stay at the identity .*but frame 6 has it 0 mm and 3°"),
        (
            "ulna",
            0.0,
            4.0,
            r"ulna must stay at its static pose relative to the radius .*within 3 mm and 10°, but frame 6",
        ),
        ("ulna", 12.0, 0.0, r"ulna must stay .*frame 6 has it [0-9.]+ mm and 12°"),
    ],
    ids=["radius shifted", "radius turned", "ulna shifted", "ulna turned"],
)
def test_a_radius_or_ulna_off_the_radius_frame_is_refused(csv_path, bone, deg, shift_mm, value):
    """The radius is the identity in its own coordinate system and the ulna nearly fixed to it: a trial
    where either moves beyond the tolerances (trial.RADIUS_TOLERANCE_*, ULNA_TOLERANCE_*) is in another
    frame; the message names the file, the frame and the deviation."""
    edit_csv(csv_path, _turn_row(bone, 6, deg, shift_mm))
    with raises(csv_path, value):
        read_trial_csv(csv_path, "u", "calibrate")


def test_the_ulna_is_checked_relative_to_the_radius(csv_path):
    """Radius and ulna moved together by as much as the radius may move, the ulna stays fixed relative
    to it: accepted (the ulna's own pose is 1.9° and 0.9 mm from the identity)."""
    edit_csv(csv_path, _turn_row("radius", 3, 1.9, 0.9))
    edit_csv(csv_path, _turn_row("ulna", 3, 1.9, 0.9))
    read_trial_csv(csv_path, "u", "calibrate")


def test_small_forearm_motion_within_tracking_noise_is_accepted(csv_path):
    """The tolerances stay above 4DCT tracking noise: a radius 0.5 mm and 1° off, an ulna 2 mm and 5°."""
    edit_csv(csv_path, _turn_row("radius", 2, 1.0, 0.5))
    edit_csv(csv_path, _turn_row("ulna", 9, 5.0, 2.0))
    read_trial_csv(csv_path, "u", "calibrate")


@pytest.mark.parametrize("name", ["P1", "P2", "P3"])
def test_the_builtin_trials_pass_the_forearm_check(name, tmp_path):
    """The built-in trials (read through read_trial_csv) and the same written by write_trial_csv."""
    from wrist_env.participants import builtin

    for trial_name, trial in builtin.trials(name).items():
        assert {"radius", "ulna"} <= set(trial.bones)
        write_trial_csv(trial, tmp_path / f"{trial_name}.csv")
        again = read_trial_csv(tmp_path / f"{trial_name}.csv", trial_name, trial.role)
        np.testing.assert_array_equal(again.transforms, trial.transforms)


def test_a_trial_of_too_many_rows_is_refused_before_it_is_parsed(tmp_path, monkeypatch):
    """More rows than MAX_TRIAL_FRAMES frames of every bone: refused with the limit, pandas never called."""
    import wrist_env.trial as trial_module

    monkeypatch.setattr(trial_module, "MAX_TRIAL_FRAMES", 10)
    path = tmp_path / "long.csv"
    write_trial_csv(make_trial(n_frames=17), path)  # 17 frames × 5 bones = 85 rows > 10 × 8 (`model.BONES`)
    monkeypatch.setattr(trial_module.pd, "read_csv", lambda *a, **k: pytest.fail("parsed"))
    with raises(path, r"at most 10 frames \(limits.MAX_TRIAL_FRAMES\), so at most 80 rows .* but the file has 85"):
        read_trial_csv(path, "u", "calibrate")


@pytest.mark.parametrize("frame", [1000, -1, 10**12])
def test_a_frame_number_beyond_the_limit_is_refused(csv_path, frame):
    """A frame numbered outside [0, MAX_TRIAL_FRAMES) is refused before the frames are counted (a frame
    10^12 once made a set of 10^12 numbers to find the gaps)."""
    edit_csv(csv_path, lambda t: t.assign(frame=t.frame.where(t.index != 30, frame)))
    with raises(csv_path, rf"n at most 1,000 \(limits.MAX_TRIAL_FRAMES\), but line 32 has frame {frame}"):
        read_trial_csv(csv_path, "u", "calibrate")
