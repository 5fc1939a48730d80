"""Checking poses and points before the frames' maths (`frames`) uses them: 4×4 homogeneous transforms with
an orthonormal, right-handed rotation and a bottom row (0, 0, 0, 1), and finite 3-D points; each refusal
names the input, where in it, and the value."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike

from wrist_env.errors import InputError

__all__ = ["ORTHONORMAL_TOL", "BOTTOM_ROW_TOL", "validate_poses", "validate_points"]

ORTHONORMAL_TOL = 1e-4  # max |RᵀR − I|
BOTTOM_ROW_TOL = 1e-9


def validate_poses(
    poses: ArrayLike,
    name: str = "poses",
    *,
    error: type = InputError,
    where: Callable[[Sequence[int]], str] | None = None,
) -> np.ndarray:
    """The poses, checked, as a float64 array.

    Rules: shape (..., 4, 4); finite; bottom row 0 0 0 1; rotation orthonormal
    (``max |RᵀR − I| <= 1e-4``) and proper (det > 0).

    Parameters
    ----------
    poses : array_like, shape (..., 4, 4)
        The poses, mm.
    name : str, default "poses"
        What they are, as a message names them.
    error : type, default InputError
        The exception raised, naming `name`, the entry and its value.
    where : callable, optional
        ``where(index)`` names an entry (default "entry (i, j)").

    Returns
    -------
    np.ndarray, shape (..., 4, 4)
        The poses as float64.
    """
    try:
        t = np.asarray(poses, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise error(f"{name}: must be an array of 4×4 transforms, but cannot be read as numbers: {exc}") from exc
    if t.ndim < 2 or t.shape[-2:] != (4, 4):
        raise error(f"{name}: must have shape (..., 4, 4), but got {t.shape}.")
    where = where or (lambda index: f"entry {_at(index)}")
    bad = ~np.isfinite(t)
    if bad.any():
        *index, r, c = np.argwhere(bad)[0]
        raise error(f"{name}: must be finite, but {where(index)} has m{r}{c}={t[(*index, r, c)]}.")
    bottom = np.abs(t[..., 3, :] - [0.0, 0.0, 0.0, 1.0]).max(axis=-1)
    if (bottom > BOTTOM_ROW_TOL).any():
        index = np.unravel_index(np.argmax(bottom), bottom.shape)
        raise error(f"{name}: the bottom row must be 0 0 0 1, but {where(index)} has {t[index][3].tolist()}.")
    rot = t[..., :3, :3]
    deviation = np.abs(np.swapaxes(rot, -1, -2) @ rot - np.eye(3)).max(axis=(-2, -1))
    if (deviation > ORTHONORMAL_TOL).any():
        index = np.unravel_index(np.argmax(deviation), deviation.shape)
        raise error(
            f"{name}: rotations must be orthonormal (max |RᵀR − I| <= {ORTHONORMAL_TOL}), "
            f"but {where(index)} has max |RᵀR − I| = {deviation[index]:.3g}."
        )
    det = np.linalg.det(rot)
    if (det <= 0).any():
        index = np.unravel_index(np.argmin(det), det.shape)
        raise error(
            f"{name}: rotations must be proper (det = +1), but {where(index)} has det = {det[index]:.6g} "
            f"(a reflection; mirror left wrists instead)."
        )
    return t


def validate_points(points: ArrayLike, name: str = "reference_point") -> np.ndarray:
    """Points (mm), checked, as a float64 array; an InputError naming `name` and the value otherwise.

    Parameters
    ----------
    points : array_like, shape (..., 3)
        The points, mm.
    name : str, default "reference_point"
        What they are, as a message names them.

    Returns
    -------
    np.ndarray, shape (..., 3)
        The points as float64.
    """
    try:
        p = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name}: must be points of 3 coordinates (mm), but cannot be read as numbers: {exc}") from exc
    if p.ndim < 1 or p.shape[-1] != 3:
        raise InputError(f"{name}: must have shape (..., 3) (x, y, z in mm), but got {p.shape}.")
    if not np.isfinite(p).all():
        index = tuple(int(i) for i in np.argwhere(~np.isfinite(p))[0])
        raise InputError(f"{name}: must be finite, but entry {index} is {p[index]}.")
    return p


def _at(index) -> str:
    return str(tuple(int(i) for i in index))
