"""Rigid-body kernels: rotations, poses and point kinematics (Numba)."""

from __future__ import annotations

import numpy as np
from numba import njit

LEVER_MM = 10.0
"""A rotation's size as a move (radians × this lever, mm): the moment tolerance is the force tolerance
× this lever, and a bone's or the capitate's move counts its rotation so."""


def pose_state(poses: np.ndarray, com0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The kernels' state (R (n, 3, 3), x (n, 3) centres of mass, mm) of one frame's poses (n, 4, 4),
    neutral → frame, of bodies whose neutral centres of mass are com0 (n, 3) mm: x = R·com0 + t."""
    R = np.ascontiguousarray(poses[:, :3, :3], dtype=np.float64)
    return R, np.ascontiguousarray(np.einsum("bij,bj->bi", R, com0) + poses[:, :3, 3])


def pose_translation(R: np.ndarray, x: np.ndarray, com0: np.ndarray) -> np.ndarray:
    """The poses' translations t (n, 3) mm of the state (R, x): t = x − R·com0 (`pose_state`'s inverse)."""
    return x - np.einsum("bij,bj->bi", R, com0)


@njit(cache=True, error_model="numpy")
def matrix_to_rotvec(R):
    """Rotation vector (3,), radians, of a rotation matrix (3, 3)."""
    c = (R[0, 0] + R[1, 1] + R[2, 2] - 1.0) * 0.5
    c = min(1.0, max(-1.0, c))
    theta = np.arccos(c)
    v = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    s = np.sin(theta)
    if theta < 1e-8:
        return 0.5 * v
    if np.pi - theta < 1e-6:
        # near pi: axis from the symmetric part
        B = 0.5 * (R + np.eye(3))
        i = np.argmax(np.array([B[0, 0], B[1, 1], B[2, 2]]))
        axis = B[:, i] / np.sqrt(max(B[i, i], 1e-300))
        return axis * theta
    return v * (theta / (2.0 * s))


@njit(cache=True, error_model="numpy")
def orthonormalize(R):
    """Nearest rotation to R by Gram–Schmidt on its columns (R is (3, 3))."""
    x = R[:, 0] / np.linalg.norm(R[:, 0])
    column = np.ascontiguousarray(R[:, 1])  # np.dot of a strided column warns (NumbaPerformanceWarning)
    y = column - np.dot(x, column) * x
    y = y / np.linalg.norm(y)
    z = np.cross(x, y)
    out = np.empty((3, 3))
    out[:, 0] = x
    out[:, 1] = y
    out[:, 2] = z
    return out


@njit(cache=True, error_model="numpy", inline="always")
def rotate_in_place(R, wx, wy, wz):
    """R ← exp([w]×) R for a rotation vector w (radians); R is (3, 3), nothing allocated."""
    theta2 = wx * wx + wy * wy + wz * wz
    if theta2 < 1e-24:
        a, c = 1.0, 0.5
    else:
        theta = np.sqrt(theta2)
        a = np.sin(theta) / theta
        c = (1.0 - np.cos(theta)) / theta2
    # E = I + a [w]× + c [w]×²
    e00 = 1.0 - c * (wy * wy + wz * wz)
    e11 = 1.0 - c * (wx * wx + wz * wz)
    e22 = 1.0 - c * (wx * wx + wy * wy)
    e01 = -a * wz + c * wx * wy
    e10 = a * wz + c * wx * wy
    e02 = a * wy + c * wx * wz
    e20 = -a * wy + c * wx * wz
    e12 = -a * wx + c * wy * wz
    e21 = a * wx + c * wy * wz
    for j in range(3):
        r0, r1, r2 = R[0, j], R[1, j], R[2, j]
        R[0, j] = e00 * r0 + e01 * r1 + e02 * r2
        R[1, j] = e10 * r0 + e11 * r1 + e12 * r2
        R[2, j] = e20 * r0 + e21 * r1 + e22 * r2


@njit(cache=True, error_model="numpy")
def interpolate_pose(R0, t0, axis, R, t, s):
    """Pose a fraction s in [0, 1] from (R0, t0) along the rotation vector `axis` = log(R1 R0ᵀ)
    and to t0 + `t` (mm): written into R (3, 3); returns the translation as a tuple."""
    R[:, :] = R0
    rotate_in_place(R, s * axis[0], s * axis[1], s * axis[2])
    return t0[0] + s * t[0], t0[1] + s * t[1], t0[2] + s * t[2]


@njit(cache=True, error_model="numpy")
def smoothstep(s):
    """C1 ramp from 0 to 1 on s in [0, 1] (zero velocity at both ends)."""
    s = min(1.0, max(0.0, s))
    return s * s * (3.0 - 2.0 * s)
