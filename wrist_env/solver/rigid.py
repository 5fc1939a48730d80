"""Rigid-body kernels: rotations, poses and point kinematics (Numba)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def rotvec_to_matrix(w):
    """Rotation matrix (3, 3) of a rotation vector (3,), radians (Rodrigues)."""
    theta = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    R = np.eye(3)
    if theta < 1e-14:
        R[0, 1] = -w[2]
        R[0, 2] = w[1]
        R[1, 0] = w[2]
        R[1, 2] = -w[0]
        R[2, 0] = -w[1]
        R[2, 1] = w[0]
        return R
    k = w / theta
    c = np.cos(theta)
    s = np.sin(theta)
    K = np.zeros((3, 3))
    K[0, 1] = -k[2]
    K[0, 2] = k[1]
    K[1, 0] = k[2]
    K[1, 2] = -k[0]
    K[2, 0] = -k[1]
    K[2, 1] = k[0]
    return R + s * K + (1.0 - c) * (K @ K)


@njit(cache=True)
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


@njit(cache=True)
def orthonormalize(R):
    """Nearest rotation to R by Gram–Schmidt on its columns (R is (3, 3))."""
    x = R[:, 0] / np.linalg.norm(R[:, 0])
    y = R[:, 1] - np.dot(x, R[:, 1]) * x
    y = y / np.linalg.norm(y)
    z = np.cross(x, y)
    out = np.empty((3, 3))
    out[:, 0] = x
    out[:, 1] = y
    out[:, 2] = z
    return out


@njit(cache=True)
def interpolate_pose(R0, t0, R1, t1, s):
    """Pose a fraction s in [0, 1] from (R0, t0) to (R1, t1): geodesic rotation, linear translation."""
    w = matrix_to_rotvec(R1 @ R0.T)
    return rotvec_to_matrix(w * s) @ R0, t0 + s * (t1 - t0)


@njit(cache=True)
def smoothstep(s):
    """C1 ramp from 0 to 1 on s in [0, 1] (zero velocity at both ends)."""
    s = min(1.0, max(0.0, s))
    return s * s * (3.0 - 2.0 * s)
