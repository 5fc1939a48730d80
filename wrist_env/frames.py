"""Frames and the 6-DOF decomposition of bone poses (the one owner of both).

Poses are 4×4 homogeneous transforms in the radius coordinate system (RCS, mm,
right wrist): x volar(+)/dorsal, y proximal(+)/distal, z radial(+)/ulnar. A pose
`T` maps a bone's neutral (static CT) vertices, in the RCS, to their place at
one frame, as in `wrist_env.trial.Trial.transforms`.

Six DOF, in the order and with the names of the preprint's Table 3 (`DOF_NAMES`):

    0 Vol/Dor    translation along x, mm, volar +
    1 Pro/Dis    translation along y, mm, proximal +
    2 Rad/Uln    translation along z, mm, radial +
    3 Flex/Ext   rotation about z, degrees, flexion +
    4 UlnD/RadD  rotation about x', degrees, ulnar deviation +
    5 Pro/Sup    rotation about y'', degrees, pronation +

Rotations are Cardan Z-X-Y angles, *intrinsic* (rotating axes): first about z,
then about the once-rotated x', then about the twice-rotated y'', so that
R = Rz(flex) · Rx(ulnar) · Ry(pronation). This is SciPy's upper-case sequence
"ZXY" (`Rotation.from_euler("ZXY", ...)`); lower-case "zxy" would be extrinsic
and is not used. Angles are in (−180, 180], the middle one in [−90, 90].

Translations depend on the point that is tracked. The preprint gives every bone
a coordinate system aligned with the RCS in the static image and placed at the
bone's centroid, so its translations are those of the centroid. Every function
here takes a `reference_point` (mm, RCS, in the neutral pose; default the RCS
origin): the translation DOF are the displacement T·c − c of that point, so the
neutral pose (identity) is all zeros for any reference point.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from wrist_env.errors import InputError
from wrist_env.pose_checks import validate_points, validate_poses

__all__ = [
    "DOF_NAMES",
    "DOF_UNITS",
    "TRANSLATION",
    "ROTATION",
    "CARDAN_SEQUENCE",
    "EXPRESSED_IN",
    "cardan_angles",
    "cardan_rotation",
    "apply",
    "invert",
    "pose_to_dof",
    "dof_to_pose",
    "error_transform",
    "error_dof",
    "error_dof_validated",
    "pose_to_dof_validated",
    "rmse",
]

DOF_NAMES = ("Vol/Dor", "Pro/Dis", "Rad/Uln", "Flex/Ext", "UlnD/RadD", "Pro/Sup")
DOF_UNITS = ("mm", "mm", "mm", "deg", "deg", "deg")
TRANSLATION = slice(0, 3)
ROTATION = slice(3, 6)
CARDAN_SEQUENCE = "ZXY"  # SciPy upper case = intrinsic: z, then x', then y''
EXPRESSED_IN = ("bone", "rcs")


def cardan_angles(rotations: ArrayLike) -> np.ndarray:
    """Cardan Z-X-Y angles (degrees) of rotation matrices; intrinsic: R = Rz(a)·Rx(b)·Ry(c).

    Parameters
    ----------
    rotations : array_like, shape (..., 3, 3)
        Rotation matrices, assumed valid (see validate_poses).

    Returns
    -------
    np.ndarray, shape (..., 3)
        Flex/Ext, UlnD/RadD, Pro/Sup, deg.
    """
    r = np.asarray(rotations, dtype=np.float64)
    lead = r.shape[:-2]
    flat = r.reshape(-1, 3, 3)
    if flat.shape[0] == 0:
        return np.zeros(lead + (3,))
    from scipy.spatial.transform import Rotation  # here: scipy.spatial costs 0.2 s to import

    return Rotation.from_matrix(flat).as_euler(CARDAN_SEQUENCE, degrees=True).reshape(lead + (3,))


def cardan_rotation(angles: ArrayLike) -> np.ndarray:
    """Rotation matrices of Cardan Z-X-Y angles; an InputError for angles of another shape or not finite.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        Flex/Ext, UlnD/RadD, Pro/Sup, deg.

    Returns
    -------
    np.ndarray, shape (..., 3, 3)
        The rotation matrices.
    """
    a = np.asarray(angles, dtype=np.float64)
    if a.ndim < 1 or a.shape[-1] != 3:
        raise InputError(
            f"angles: must have shape (..., 3) (Flex/Ext, UlnD/RadD, Pro/Sup in degrees), but got {a.shape}."
        )
    if not np.isfinite(a).all():
        raise InputError(f"angles: must be finite, but got {a[~np.isfinite(a)][0]}.")
    lead = a.shape[:-1]
    flat = a.reshape(-1, 3)
    if flat.shape[0] == 0:
        return np.zeros(lead + (3, 3))
    from scipy.spatial.transform import Rotation  # here: scipy.spatial costs 0.2 s to import

    return Rotation.from_euler(CARDAN_SEQUENCE, flat, degrees=True).as_matrix().reshape(lead + (3, 3))


def apply(poses: ArrayLike, points: ArrayLike) -> np.ndarray:
    """Points moved by poses: R·p + t, broadcast over leading axes.

    Parameters
    ----------
    poses : array_like, shape (..., 4, 4)
        The poses, mm.
    points : array_like, shape (..., 3)
        The points, mm.

    Returns
    -------
    np.ndarray, shape (..., 3)
        The moved points, mm.
    """
    t = np.asarray(poses, dtype=np.float64)
    p = np.asarray(points, dtype=np.float64)
    return (t[..., :3, :3] @ p[..., :, None])[..., 0] + t[..., :3, 3]


def invert(poses: ArrayLike) -> np.ndarray:
    """Inverses of rigid transforms: [Rᵀ, −Rᵀt; 0 0 0 1].

    Parameters
    ----------
    poses : array_like, shape (..., 4, 4)
        Rigid transforms.

    Returns
    -------
    np.ndarray, shape (..., 4, 4)
        Their inverses.
    """
    t = np.asarray(poses, dtype=np.float64)
    out = np.zeros_like(t)
    rt = np.swapaxes(t[..., :3, :3], -1, -2)
    out[..., :3, :3] = rt
    out[..., :3, 3] = -(rt @ t[..., :3, 3, None])[..., 0]
    out[..., 3, 3] = 1.0
    return out


def pose_to_dof(poses: ArrayLike, reference_point: ArrayLike | None = None) -> np.ndarray:
    """Six DOF of poses: the displacement of a reference point, then Cardan angles.

    Parameters
    ----------
    poses : array_like, shape (..., 4, 4)
        The poses, mm.
    reference_point : array_like, shape (3,), optional
        Or broadcastable to poses.shape[:-2] + (3,), mm, RCS, neutral pose; None = the RCS origin (the
        translation column of T). For per-bone points with poses of shape (n_bones, n_frames, 4, 4) pass
        shape (n_bones, 1, 3).

    Returns
    -------
    np.ndarray, shape (..., 6)
        Displacement T·c − c (mm, RCS) of the reference point c, then Cardan angles (deg).
    """
    t = validate_poses(poses)
    c = np.zeros(3) if reference_point is None else validate_points(reference_point)
    return _dof(t, c)


def dof_to_pose(dof: ArrayLike, reference_point: ArrayLike | None = None) -> np.ndarray:
    """Poses of six DOF: the inverse of pose_to_dof with the same reference point.

    Parameters
    ----------
    dof : array_like, shape (..., 6)
        Six DOF, mm and deg (`DOF_NAMES`).
    reference_point : array_like, shape (3,), optional
        As pose_to_dof's.

    Returns
    -------
    np.ndarray, shape (..., 4, 4)
        The poses.
    """
    d = np.asarray(dof, dtype=np.float64)
    if d.ndim < 1 or d.shape[-1] != 6:
        raise InputError(f"dof: must have shape (..., 6) ({', '.join(DOF_NAMES)}), but got {d.shape}.")
    if not np.isfinite(d).all():
        index = tuple(int(i) for i in np.argwhere(~np.isfinite(d))[0])
        raise InputError(f"dof: must be finite, but entry {index} ({DOF_NAMES[index[-1]]}) is {d[index]}.")
    c = np.zeros(3) if reference_point is None else validate_points(reference_point)
    rot = cardan_rotation(d[..., ROTATION])
    # T·c − c = d  ⇒  t = d + c − R·c
    translation = d[..., TRANSLATION] + c - (rot @ c[..., :, None])[..., 0]
    lead = np.broadcast_shapes(rot.shape[:-2], translation.shape[:-1])
    out = np.zeros(lead + (4, 4))
    out[..., :3, :3] = rot
    out[..., :3, 3] = translation
    out[..., 3, 3] = 1.0
    return out


def error_transform(model: ArrayLike, experiment: ArrayLike, *, expressed_in: str = "bone") -> np.ndarray:
    """Error transforms between model and experimental poses of one bone, frame by frame.

    Parameters
    ----------
    model, experiment : array_like, shape (..., 4, 4)
        The model's and the experiment's poses, mm, of one shape.
    expressed_in : {"bone", "rcs"}, default "bone"
        "bone": E = T_exp⁻¹ · T_model, the model bone's pose relative to the experimental bone, in the
        experimental bone's coordinate system (RCS-aligned in the neutral pose); identical poses give the
        identity. "rcs": E = T_model · T_exp⁻¹, the motion in the RCS that carries the experimental bone
        onto the model bone.

    Returns
    -------
    np.ndarray, shape (..., 4, 4)
        The error transforms.
    """
    m = validate_poses(model, "model poses")
    e = validate_poses(experiment, "experimental poses")
    _same_shape(m, e)
    return _error_transform(m, e, expressed_in)


def _error_transform(m: np.ndarray, e: np.ndarray, expressed_in: str) -> np.ndarray:
    if expressed_in == "bone":
        return invert(e) @ m
    if expressed_in == "rcs":
        return m @ invert(e)
    raise InputError(f"expressed_in must be one of {EXPRESSED_IN}, but got {expressed_in!r}.")


def error_dof(
    model: ArrayLike, experiment: ArrayLike, reference_point: ArrayLike | None = None, *, expressed_in: str = "bone"
) -> np.ndarray:
    """Six-DOF error of model vs experimental poses (mm, deg), model minus experiment.

    The rotation DOF are the Cardan Z-X-Y angles of the error transform's rotation; the
    translation DOF are the displacement of the bone's reference point c.

    Parameters
    ----------
    model, experiment : array_like, shape (..., 4, 4)
        The model's and the experiment's poses, mm, of one shape.
    reference_point : array_like, shape (3,), optional
        c, mm, RCS, neutral pose; default the RCS origin (the preprint tracks the centroid).
    expressed_in : {"bone", "rcs"}, default "bone"
        "bone": R_expᵀ · (T_model·c − T_exp·c), angles of R_expᵀ·R_model (experimental bone's axes);
        "rcs": T_model·c − T_exp·c, angles of R_model·R_expᵀ (RCS axes).

    Returns
    -------
    np.ndarray, shape (..., 6)
        The error, mm and deg (`DOF_NAMES`).
    """
    m = validate_poses(model, "model poses")
    e = validate_poses(experiment, "experimental poses")
    _same_shape(m, e)
    c = np.zeros(3) if reference_point is None else validate_points(reference_point)
    return error_dof_validated(m, e, c, expressed_in=expressed_in)


def error_dof_validated(
    model: np.ndarray, experiment: np.ndarray, point: np.ndarray, *, expressed_in: str = "bone"
) -> np.ndarray:
    """`error_dof` of inputs already checked, for callers that validate once and evaluate many times (the cost).

    Parameters
    ----------
    model, experiment : np.ndarray, shape (..., 4, 4)
        Poses, mm, checked by `validate_poses`, of one shape.
    point : np.ndarray, shape (..., 3)
        The reference point, mm, checked by `validate_points`.
    expressed_in : {"bone", "rcs"}, default "bone"
        As `error_dof`'s.

    Returns
    -------
    np.ndarray, shape (..., 6)
        The error, mm and deg.
    """
    error = _error_transform(model, experiment, expressed_in)
    c = point if expressed_in == "bone" else apply(experiment, point)
    # not re-validated: a product of two poses within the orthonormality tolerance may exceed it
    return _dof(error, c)


def pose_to_dof_validated(poses: np.ndarray, point: np.ndarray) -> np.ndarray:
    """`pose_to_dof` of poses and a point already checked (`validate_poses`, `validate_points`).

    Parameters
    ----------
    poses : np.ndarray, shape (..., 4, 4)
        The poses, mm.
    point : np.ndarray, shape (..., 3)
        The reference point, mm.

    Returns
    -------
    np.ndarray, shape (..., 6)
        The six DOF, mm and deg.
    """
    return _dof(poses, point)


def rmse(
    model: ArrayLike, experiment: ArrayLike, reference_point: ArrayLike | None = None, *, expressed_in: str = "bone"
) -> np.ndarray:
    """Per-DOF root mean squared error over frames (mm, deg), as in the preprint's Tables 3–4.

    The RMSE of error_dof over the frame axis (axis −3 of the poses).

    Parameters
    ----------
    model, experiment : array_like, shape (..., n_frames, 4, 4)
        The model's and the experiment's poses, mm, of one shape.
    reference_point : array_like, shape (3,), optional
        As error_dof's; for per-bone points with poses (n_bones, n_frames, 4, 4) pass shape (n_bones, 1, 3).
    expressed_in : {"bone", "rcs"}, default "bone"
        As error_dof's.

    Returns
    -------
    np.ndarray, shape (..., 6)
        The RMSE of each DOF, mm and deg.
    """
    e = validate_poses(experiment, "experimental poses")
    if e.ndim < 3:
        raise InputError(f"experimental poses: must have shape (..., n_frames, 4, 4), but got {e.shape}.")
    err = error_dof(model, e, reference_point, expressed_in=expressed_in)
    return np.sqrt(np.mean(err**2, axis=-2))


def _dof(t: np.ndarray, c: np.ndarray) -> np.ndarray:
    """pose_to_dof of validated poses and points."""
    displacement = apply(t, c) - c
    angles = cardan_angles(t[..., :3, :3])
    displacement, angles = np.broadcast_arrays(displacement, angles)
    return np.concatenate([displacement, angles], axis=-1)


def _same_shape(model: np.ndarray, experiment: np.ndarray) -> None:
    if model.shape != experiment.shape:
        raise InputError(
            f"model and experimental poses must have the same shape, but got {model.shape} and {experiment.shape}."
        )
