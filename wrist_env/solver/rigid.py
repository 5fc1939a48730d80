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
    out = np.empty(3)
    c = (R[0, 0] + R[1, 1] + R[2, 2] - 1.0) * 0.5
    c = min(1.0, max(-1.0, c))
    theta = np.arccos(c)
    if np.pi - theta < 1e-6:
        # near pi: the axis is the largest column of the symmetric part (R + I) / 2
        i = 0
        for k in range(1, 3):
            if R[k, k] > R[i, i]:
                i = k
        scale = theta / np.sqrt(max(0.5 * (R[i, i] + 1.0), 1e-300))
        for k in range(3):
            out[k] = 0.5 * (R[k, i] + (1.0 if k == i else 0.0)) * scale
        return out
    scale = 0.5 if theta < 1e-8 else theta / (2.0 * np.sin(theta))
    out[0] = (R[2, 1] - R[1, 2]) * scale
    out[1] = (R[0, 2] - R[2, 0]) * scale
    out[2] = (R[1, 0] - R[0, 1]) * scale
    return out


@njit(cache=True, error_model="numpy")
def rotvec_between(A, B):
    """Rotation vector (3,), radians, of A Bᵀ (rotations (3, 3)): B's turn to A."""
    C = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            C[i, j] = A[i, 0] * B[j, 0] + A[i, 1] * B[j, 1] + A[i, 2] * B[j, 2]
    return matrix_to_rotvec(C)


@njit(cache=True, error_model="numpy")
def orthonormalize(R):
    """R (3, 3) ← the nearest rotation by Gram–Schmidt on its columns, in place."""
    n = np.sqrt(R[0, 0] ** 2 + R[1, 0] ** 2 + R[2, 0] ** 2)
    x0, x1, x2 = R[0, 0] / n, R[1, 0] / n, R[2, 0] / n
    d = x0 * R[0, 1] + x1 * R[1, 1] + x2 * R[2, 1]
    y0, y1, y2 = R[0, 1] - d * x0, R[1, 1] - d * x1, R[2, 1] - d * x2
    n = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
    y0, y1, y2 = y0 / n, y1 / n, y2 / n
    R[0, 0], R[1, 0], R[2, 0] = x0, x1, x2
    R[0, 1], R[1, 1], R[2, 1] = y0, y1, y2
    R[0, 2], R[1, 2], R[2, 2] = x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0


@njit(cache=True, error_model="numpy")
def copy_into(dst, src):
    """dst ← src for C-contiguous arrays of one size, element by element (an array assignment makes
    Numba compile its broadcasting checks and their messages: seconds of a cold start each)."""
    d, s = dst.reshape(-1), src.reshape(-1)
    for i in range(d.shape[0]):
        d[i] = s[i]


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
    for i in range(3):
        for j in range(3):
            R[i, j] = R0[i, j]
    rotate_in_place(R, s * axis[0], s * axis[1], s * axis[2])
    return t0[0] + s * t[0], t0[1] + s * t[1], t0[2] + s * t[2]


@njit(cache=True, error_model="numpy")
def smoothstep(s):
    """C1 ramp from 0 to 1 on s in [0, 1] (zero velocity at both ends)."""
    s = min(1.0, max(0.0, s))
    return s * s * (3.0 - 2.0 * s)
