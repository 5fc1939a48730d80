"""Kinematic trials: rigid bone poses per frame as 4×4 transforms in the RCS (mm).

`transforms[b, f]` maps the vertices of bone b in the neutral (static CT)
pose, expressed in the RCS, to their pose at frame f; the radius is close to
the identity. CSV format, one row per bone per frame, frames 0..n-1:

    frame,bone,m00,m01,m02,m03,m10,m11,m12,m13,m20,m21,m22,m23

(the top three rows of the 4×4; the bottom row is 0 0 0 1).

The RCS is the radius's own frame, and the solver holds the radius and ulna
fixed in it: rows of the radius, where given, must be the identity on every
frame (within `RADIUS_TOLERANCE_MM` and `RADIUS_TOLERANCE_DEG`), and rows of
the ulna nearly fixed relative to the radius (`ULNA_TOLERANCE_MM`,
`ULNA_TOLERANCE_DEG`); otherwise the trial is in another frame (scanner
coordinates, say). A trial has at most `limits.MAX_TRIAL_FRAMES` frames.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from wrist_env.errors import TrialError
from wrist_env.limits import MAX_TRIAL_FRAMES
from wrist_env.model import BONES, CARPALS
from wrist_env.motions import TRIAL_MOTIONS
from wrist_env.pose_checks import validate_poses

__all__ = [
    "ROLES",
    "REQUIRED_BONES",
    "MATRIX_COLUMNS",
    "COLUMNS",
    "METRES_TRANSLATION_MM",
    "METRES_ROTATION_DEG",
    "MAX_TRANSLATION_MM",
    "RADIUS_TOLERANCE_MM",
    "RADIUS_TOLERANCE_DEG",
    "ULNA_TOLERANCE_MM",
    "ULNA_TOLERANCE_DEG",
    "MIRROR",
    "Trial",
    "mirror_trial",
    "validate_transforms",
    "read_trial_csv",
    "write_trial_csv",
]

ROLES = TRIAL_MOTIONS + ("other",)
REQUIRED_BONES = CARPALS
MATRIX_COLUMNS = tuple(f"m{r}{c}" for r in range(3) for c in range(4))
COLUMNS = ("frame", "bone") + MATRIX_COLUMNS
METRES_TRANSLATION_MM = 0.5  # all |t| below this while rotations vary ...
METRES_ROTATION_DEG = 5.0  # ... by more than this: translations are in metres
MAX_TRANSLATION_MM = 100.0
"""A bone's pose moves it at most this far (mm, any axis) from its neutral place: the built-in trials stay
within 8 mm; a larger value is a unit or export error (1e6 mm was accepted, at cost 1.4e6)."""
RADIUS_TOLERANCE_MM, RADIUS_TOLERANCE_DEG = 1.0, 2.0
"""How far the radius may be from the identity on a frame (translation of the RCS origin, rotation angle).
In the radius's own frame the radius is the identity by definition; what remains is tracking noise (the
built-in trials' 0.2 mm and 0.5° RMS: `builtin.TRACKING_NOISE_MM`/`_DEG`), which stays well inside 5× and 4×
that. A radius moved further shifts every carpal's reference by more than the errors calibration resolves
(~1 mm, ~2°): a trial in scanner coordinates, or a forearm that moved in the scanner."""
ULNA_TOLERANCE_MM, ULNA_TOLERANCE_DEG = 3.0, 10.0
"""How far the ulna may move relative to the radius (its pose in the radius's, which is its static pose: the
identity). The distal radioulnar joint moves a little during wrist motions with the forearm held (ulnar
variance grows by ~1–2 mm in a power grip; a few degrees of rotation), which the solver ignores (both bones
fixed); more is forearm rotation the model cannot follow, or an ulna in another frame."""
MIRROR = np.diag([1.0, 1.0, -1.0, 1.0])
"""Left → right wrist reflection of the RCS (z → −z)."""


@dataclass(frozen=True, eq=False)
class Trial:
    """One motion trial of a participant.

    Parameters
    ----------
    name : str
        The trial's name, e.g. "unresisted".
    role : str
        "calibrate", "validate" or "other" (`ROLES`).
    bones : tuple of str
        Bone names, a subset of BONES in BONES order.
    transforms : np.ndarray, shape (n_bones, n_frames, 4, 4)
        float64, mm; neutral pose → frame f, RCS (`validate_transforms`: a TrialError otherwise); n_frames >= 2.
    load_n : np.ndarray, shape (n_frames,), optional
        The total tendon load of each frame, N, where it is known (the built-in trials' truth runs), else
        None (taken as 0: the bones not prescribed by the trial move unloaded).
    """

    name: str
    role: str
    bones: tuple[str, ...]
    transforms: np.ndarray
    load_n: np.ndarray | None = None

    def __post_init__(self):
        if self.role not in ROLES:
            raise TrialError(f"trial {self.name!r}: role must be one of {ROLES}, but got {self.role!r}.")
        bones = tuple(self.bones)
        unknown = [b for b in bones if b not in BONES]
        if unknown or len(set(bones)) != len(bones):
            raise TrialError(f"trial {self.name!r}: bones must be distinct names from {BONES}, but got {bones}.")
        transforms = validate_transforms(self.transforms, f"trial {self.name!r}", bones)
        if transforms.ndim != 4 or transforms.shape[0] != len(bones) or transforms.shape[1] < 2:
            raise TrialError(
                f"trial {self.name!r}: transforms must have shape ({len(bones)}, n_frames >= 2, 4, 4), "
                f"but got {transforms.shape}."
            )
        transforms = transforms.copy()
        transforms.setflags(write=False)
        object.__setattr__(self, "bones", bones)
        object.__setattr__(self, "transforms", transforms)
        if self.load_n is not None:
            load = np.array(self.load_n, dtype=np.float64)
            if load.shape != (transforms.shape[1],) or not np.isfinite(load).all() or (load < 0).any():
                raise TrialError(
                    f"trial {self.name!r}: load_n must be finite, >= 0 N, one per frame ({transforms.shape[1]},), "
                    f"but got shape {load.shape}, values {load.ravel()[:5]}"
                )
            load.setflags(write=False)
            object.__setattr__(self, "load_n", load)

    @property
    def n_frames(self) -> int:
        return self.transforms.shape[1]

    def pose(self, bone: str) -> np.ndarray:
        """Transforms of one bone, array of shape (n_frames, 4, 4), mm."""
        if bone not in self.bones:
            raise TrialError(f"trial {self.name!r} has no bone {bone!r}; it has {self.bones}.")
        return self.transforms[self.bones.index(bone)]


def mirror_trial(trial: Trial) -> Trial:
    """The trial of the mirror-image wrist (left ↔ right).

    Parameters
    ----------
    trial : Trial
        A trial in the RCS of one side (left or right).

    Returns
    -------
    Trial
        The same trial, each transform conjugated by diag(1, 1, −1, 1) (`MIRROR`).
    """
    return Trial(trial.name, trial.role, trial.bones, MIRROR @ trial.transforms @ MIRROR, trial.load_n)


def validate_transforms(array: ArrayLike, source: str, bones: tuple[str, ...] | None = None) -> np.ndarray:
    """The transforms, checked, as a float64 array.

    Rules: finite; bottom row 0 0 0 1; rotation orthonormal (``max |RᵀR − I| <= 1e-4``) and proper
    (det > 0); translations in mm, not metres, and within `MAX_TRANSLATION_MM`.

    Parameters
    ----------
    array : array_like, shape (..., 4, 4)
        The transforms, mm.
    source : str
        What they are, as a message names it.
    bones : tuple of str, optional
        The names of axis 0 of a (n_bones, n_frames, 4, 4) array.

    Returns
    -------
    np.ndarray, shape (..., 4, 4)
        The transforms as float64.

    Raises
    ------
    TrialError
        A rule broken (the message names `source` and the entry).
    """
    shape = np.shape(array)

    def where(index) -> str:
        index = tuple(int(i) for i in index)
        if len(shape) == 4 and bones is not None:
            return f"bone {bones[index[0]]!r} frame {index[1]}"
        if len(shape) == 3:
            return f"frame {index[0]}"
        return f"index {index}"

    t = validate_poses(array, source, error=TrialError, where=where)
    rot = t[..., :3, :3]
    if t.ndim >= 3:
        # rotation of every frame relative to the first frame of the same bone
        relative = np.swapaxes(rot[..., :1, :, :], -1, -2) @ rot
        cos = np.clip((np.trace(relative, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
        span_deg = float(np.degrees(np.arccos(cos)).max())
        max_t = float(np.abs(t[..., :3, 3]).max())
        if max_t > MAX_TRANSLATION_MM:
            worst = np.unravel_index(int(np.argmax(np.abs(t[..., :3, 3]).max(axis=-1))), t.shape[:-2])
            raise TrialError(
                f"{source}: translations must stay within {MAX_TRANSLATION_MM:g} mm of the neutral pose, but "
                f"{where(worst)} is {max_t:.4g} mm away."
            )
        if max_t < METRES_TRANSLATION_MM and span_deg > METRES_ROTATION_DEG:
            raise TrialError(
                f"{source}: translations look like metres; use mm (largest |t| = {max_t:.3g} "
                f"while rotations vary by {span_deg:.1f}°)."
            )
    return t


def read_trial_csv(
    path: str | Path,
    name: str,
    role: str,
    required_bones: tuple[str, ...] = REQUIRED_BONES,
    n_frames: int | None = None,
) -> Trial:
    """A Trial from a CSV of 4×4 transforms (mm, RCS) per bone per frame (the module docstring's format).

    Parameters
    ----------
    path : str or Path
        The CSV file.
    name : str
        The trial's name.
    role : str
        Its role (`ROLES`).
    required_bones : tuple of str, default REQUIRED_BONES
        The bones the file must have.
    n_frames : int, optional
        The number of frames it must have, if given.

    Returns
    -------
    Trial
        The trial, without loads.

    Raises
    ------
    TrialError
        A file missing or not valid (the message names it).
    """
    path = Path(path)
    if not path.is_file():
        raise TrialError(f"trial file {path} does not exist.")
    _check_row_count(path)
    try:
        table = pd.read_csv(path, skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise TrialError(f"{path}: cannot parse as CSV: {exc}") from exc
    table.columns = [str(c).strip() for c in table.columns]
    missing = [c for c in COLUMNS if c not in table.columns]
    extra = [c for c in table.columns if c not in COLUMNS]
    if missing or extra:
        raise TrialError(f"{path}: columns must be {','.join(COLUMNS)}, but {missing=} and {extra=}.")
    if table.empty:
        raise TrialError(f"{path}: the file has a header but no rows.")
    for column in ("frame",) + MATRIX_COLUMNS:
        values = pd.to_numeric(table[column], errors="coerce")
        bad = values.isna() & table[column].notna()
        if column == "frame":
            bad |= values.isna() | (values != np.round(values))
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            kind = "integers" if column == "frame" else "numbers"
            raise TrialError(
                f"{path}: column {column} must hold {kind}, but line {row + 2} has {str(table[column].iloc[row])!r}."
            )
        if column == "frame" and not values.between(0, MAX_TRIAL_FRAMES - 1).all():
            row = int(np.flatnonzero(~values.between(0, MAX_TRIAL_FRAMES - 1))[0])
            raise TrialError(
                f"{path}: frames must be numbered 0..n-1 with n at most {MAX_TRIAL_FRAMES:,} "
                f"(limits.MAX_TRIAL_FRAMES), but line {row + 2} has frame {str(table[column].iloc[row])}."
            )
        table[column] = values
    table["frame"] = table["frame"].astype(np.int64)
    table["bone"] = table["bone"].astype(str).str.strip()

    unknown = sorted(set(table["bone"]) - set(BONES))
    if unknown:
        row = int(np.flatnonzero(table["bone"] == unknown[0])[0])
        raise TrialError(f"{path}: bone names must be lower case from {BONES}, but line {row + 2} has {unknown[0]!r}.")
    duplicated = table.duplicated(["frame", "bone"])
    if duplicated.any():
        row = int(np.flatnonzero(duplicated)[0])
        raise TrialError(
            f"{path}: each (frame, bone) must appear once, but line {row + 2} repeats "
            f"frame {table['frame'].iloc[row]} bone {table['bone'].iloc[row]!r}."
        )
    bones = tuple(b for b in BONES if b in set(table["bone"]))
    absent = [b for b in required_bones if b not in bones]
    if absent:
        raise TrialError(f"{path}: bones {list(required_bones)} are required, but {absent} are missing.")

    frames = {b: set(table.loc[table["bone"] == b, "frame"]) for b in bones}
    every = set().union(*frames.values())
    for b in bones:
        if frames[b] != every:
            raise TrialError(
                f"{path}: every bone must have a row for every frame, but bone {b!r} lacks frames "
                f"{_brief(sorted(every - frames[b]))}."
            )
    first, last = min(every), max(every)
    gaps = sorted(set(range(first, last + 1)) - every)
    if first != 0 or gaps:
        raise TrialError(
            f"{path}: frames must run 0..n-1 without gaps, but they run {first}..{last} with {_brief(gaps)} missing."
        )
    if len(every) < 2:
        raise TrialError(f"{path}: a trial needs at least 2 frames, but got {len(every)}.")
    if n_frames is not None and len(every) != n_frames:
        raise TrialError(f"{path}: the trial must have {n_frames=} frames, but has {len(every)}.")

    order = np.lexsort((table["bone"].map(bones.index).to_numpy(), table["frame"].to_numpy()))
    matrix = table.loc[:, list(MATRIX_COLUMNS)].to_numpy(np.float64)[order].reshape(len(every), len(bones), 3, 4)
    transforms = np.zeros((len(bones), len(every), 4, 4))
    transforms[:, :, :3, :] = matrix.transpose(1, 0, 2, 3)
    transforms[:, :, 3, 3] = 1.0
    transforms = validate_transforms(transforms, str(path), bones)
    _check_forearm(transforms, bones, path)
    return Trial(name, role, bones, transforms)


def write_trial_csv(trial: Trial, path: str | Path) -> None:
    """Write the trial as CSV (rows frame-major, bones in BONES order; exact float round trip).

    Parameters
    ----------
    trial : Trial
        The trial (its loads are not written).
    path : str or Path
        The CSV file.
    """
    n_bones, n_frames = trial.transforms.shape[:2]
    matrix = trial.transforms[:, :, :3, :].transpose(1, 0, 2, 3).reshape(n_frames * n_bones, 12)
    table = pd.DataFrame(matrix, columns=list(MATRIX_COLUMNS))
    table.insert(0, "bone", np.tile(trial.bones, n_frames))
    table.insert(0, "frame", np.repeat(np.arange(n_frames), n_bones))
    table.to_csv(Path(path), index=False, float_format="%.17g")


def _check_row_count(path: Path, chunk: int = 1 << 24) -> None:
    """TrialError naming the file if it has more rows than a trial of `MAX_TRIAL_FRAMES` frames of every
    bone: counted in chunks, before pandas reads (and allocates) it."""
    rows, most = -1, MAX_TRIAL_FRAMES * len(BONES)  # -1: the header
    with open(path, "rb") as f:
        last = b"\n"
        while block := f.read(chunk):
            rows += block.count(b"\n")
            last = block[-1:]
    rows += last != b"\n"  # a last line without its newline
    if rows > most:
        raise TrialError(
            f"{path}: a trial has at most {MAX_TRIAL_FRAMES:,} frames (limits.MAX_TRIAL_FRAMES), so at most "
            f"{most:,} rows of its {len(BONES)} bones, but the file has {rows:,}; subsample it."
        )


def _check_forearm(transforms: np.ndarray, bones: tuple[str, ...], path: Path) -> None:
    """TrialError naming the file, the frame and the deviation unless the radius (if given) is the identity
    and the ulna (if given) nearly fixed relative to it on every frame (module docstring; tolerances
    `RADIUS_TOLERANCE_*`, `ULNA_TOLERANCE_*`)."""
    identity = np.eye(4)
    radius = transforms[bones.index("radius")] if "radius" in bones else np.broadcast_to(identity, transforms.shape[1:])
    checks = (
        [("radius", radius, "the identity", RADIUS_TOLERANCE_MM, RADIUS_TOLERANCE_DEG)] if "radius" in bones else []
    )
    if "ulna" in bones:
        relative = np.linalg.inv(radius) @ transforms[bones.index("ulna")]
        checks.append(
            ("ulna", relative, "its static pose relative to the radius", ULNA_TOLERANCE_MM, ULNA_TOLERANCE_DEG)
        )
    for bone, poses, where, most_mm, most_deg in checks:
        shift_mm = np.linalg.norm(poses[:, :3, 3], axis=1)
        cos = np.clip((np.trace(poses[:, :3, :3], axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
        turn_deg = np.degrees(np.arccos(cos))
        bad = np.flatnonzero((shift_mm > most_mm) | (turn_deg > most_deg))
        if bad.size:
            f = int(bad[0])
            raise TrialError(
                f"{path}: the {bone} must stay at {where} (the trial is in the radius's coordinate system, with "
                f"radius and ulna fixed) within {most_mm:g} mm and {most_deg:g}°, but frame {f} has it "
                f"{shift_mm[f]:.3g} mm and {turn_deg[f]:.3g}° away ({bad.size} frames in all); is the trial in "
                f"another frame (scanner coordinates)? Express every pose relative to the radius."
            )


def _brief(values: list, limit: int = 10) -> str:
    """A list for a message, cut to `limit` entries."""
    return str(values) if len(values) <= limit else f"{values[:limit]}... ({len(values)} in all)"
