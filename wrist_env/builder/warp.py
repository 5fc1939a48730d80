"""Smooth participant-specific spatial warps that make synthetic participants.

A warp maps a template point x (mm) to

    y = centre + scale · (x − centre + d(x)),   d(x) = Σ_j w_j · exp(−|x − c_j|² / (2 σ²)),

an isotropic scale about `centre` after a displacement field d made of
Gaussian radial basis functions (centres c_j, weights w_j in mm, width σ in
mm). The map is a diffeomorphism when the displacement gradient has norm
below 1; `Warp` enforces the sufficient bound Σ_j |w_j| · e^(−1/2) / σ < 1,
so the Jacobian determinant is positive everywhere and meshes keep their
winding.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from wrist_env.errors import InputError, MeshError
from wrist_env.io import fields_equal

_GRADIENT_PEAK = float(np.exp(-0.5))  # σ · max_x |∇ exp(−|x − c|² / (2σ²))|


def _points(points, name: str = "points") -> np.ndarray:
    p = np.asarray(points, dtype=np.float64)
    if p.size == 0 and p.ndim < 2:
        p = p.reshape(0, 3)
    if p.ndim != 2 or p.shape[1] != 3:
        raise InputError(f"`{name}` must have shape (n, 3), but got shape {p.shape}.")
    if not np.isfinite(p).all():
        bad = np.flatnonzero(~np.isfinite(p).all(axis=1))
        raise InputError(
            f"`{name}` must be finite, but row {bad[0]} is {p[bad[0]].tolist()} ({len(bad)} non-finite rows)."
        )
    return p


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=np.float64)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class Warp:
    """Isotropic scale about a centre after a Gaussian RBF displacement field.

    scale: isotropic scale factor (> 0).
    centre: array of shape (3,), mm, fixed point of the scale.
    rbf_centres: array of shape (k, 3), mm.
    rbf_weights: array of shape (k, 3), mm, displacement carried by each basis function.
    width_mm: Gaussian width σ of every basis function.
    """

    scale: float
    centre: np.ndarray
    rbf_centres: np.ndarray
    rbf_weights: np.ndarray
    width_mm: float

    def __post_init__(self):
        scale, width = float(self.scale), float(self.width_mm)
        if not (np.isfinite(scale) and scale > 0):
            raise InputError(f"`scale > 0` must hold, but got scale={self.scale!r}.")
        if not (np.isfinite(width) and width > 0):
            raise InputError(f"`width_mm > 0` must hold, but got width_mm={self.width_mm!r}.")
        centre = np.asarray(self.centre, dtype=np.float64)
        if centre.shape != (3,) or not np.isfinite(centre).all():
            raise InputError(f"`centre` must be 3 finite numbers, but got {np.asarray(self.centre).tolist()}.")
        c, w = _points(self.rbf_centres, "rbf_centres"), _points(self.rbf_weights, "rbf_weights")
        if c.shape != w.shape:
            raise InputError(
                f"`rbf_centres` and `rbf_weights` must have the same shape, but got {c.shape} and {w.shape}."
            )
        bound = float(np.linalg.norm(w, axis=1).sum()) * _GRADIENT_PEAK / width
        if bound >= 1.0:
            raise InputError(
                f"the warp must be a diffeomorphism: `sum |w| · exp(-1/2) / width_mm < 1` must hold, "
                f"but got {bound:.3f} (width_mm={width})."
            )
        object.__setattr__(self, "scale", scale)
        object.__setattr__(self, "width_mm", width)
        object.__setattr__(self, "centre", _frozen(centre))
        object.__setattr__(self, "rbf_centres", _frozen(c))
        object.__setattr__(self, "rbf_weights", _frozen(w))

    def __eq__(self, other) -> bool:
        if not isinstance(other, Warp):
            return NotImplemented
        return fields_equal(self, other, ("scale", "width_mm"), ("centre", "rbf_centres", "rbf_weights"))

    __hash__ = None

    def displacement(self, points: ArrayLike) -> np.ndarray:
        """RBF displacement d(x) before scaling, array of shape (n, 3), mm, at points of shape (n, 3), mm."""
        p = _points(points)
        g = self._gaussians(p)
        return g @ self.rbf_weights

    def apply(self, points: ArrayLike) -> np.ndarray:
        """Warped points, array of shape (n, 3), mm, of points of shape (n, 3), mm."""
        p = _points(points)
        return self.centre + self.scale * (p - self.centre + self._gaussians(p) @ self.rbf_weights)

    def jacobian(self, points: ArrayLike) -> np.ndarray:
        """Jacobian dy/dx, array of shape (n, 3, 3), at points of shape (n, 3), mm."""
        p = _points(points)
        g = self._gaussians(p)
        diff = p[:, None, :] - self.rbf_centres[None, :, :]  # (n, k, 3)
        grad_g = -g[:, :, None] * diff / self.width_mm**2  # (n, k, 3): d g_j / d x
        grad_d = np.einsum("ka,nkb->nab", self.rbf_weights, grad_g)  # d d_a / d x_b
        return self.scale * (np.eye(3) + grad_d)

    def jacobian_det(self, points: ArrayLike) -> np.ndarray:
        """Jacobian determinant (local volume ratio), array of shape (n,), at points of shape (n, 3), mm."""
        return np.linalg.det(self.jacobian(points))

    def as_dict(self) -> dict:
        """JSON-able parameters (lists of floats)."""
        return {
            "scale": self.scale,
            "centre": self.centre.tolist(),
            "rbf_centres": self.rbf_centres.tolist(),
            "rbf_weights": self.rbf_weights.tolist(),
            "width_mm": self.width_mm,
        }

    @classmethod
    def from_dict(cls, data: dict) -> Warp:
        """The warp from `as_dict` output."""
        keys = {"scale", "centre", "rbf_centres", "rbf_weights", "width_mm"}
        if not isinstance(data, dict) or set(data) != keys:
            got = sorted(data) if isinstance(data, dict) else type(data).__name__
            raise InputError(f"a warp must be a dict with keys {sorted(keys)}, but got {got}.")
        return cls(**data)

    def _gaussians(self, p: np.ndarray) -> np.ndarray:
        d2 = ((p[:, None, :] - self.rbf_centres[None, :, :]) ** 2).sum(axis=-1)
        return np.exp(-d2 / (2.0 * self.width_mm**2))


def random_warp(
    seed: int | None,
    *,
    scale_sd: float = 0.05,
    amplitude_mm: float = 1.0,
    width_mm: float = 15.0,
    centre: ArrayLike = (0.0, 0.0, 0.0),
    n_centres: int = 6,
    extent_mm: float = 30.0,
) -> Warp:
    """A random warp, deterministic for a seed.

    scale = exp(N(0, scale_sd)); `n_centres` RBF centres uniform in the cube
    of half-side `extent_mm` (mm) about `centre`; each weight a uniformly
    random direction of length `amplitude_mm` (mm); Gaussian width `width_mm`.
    """
    for name, value in (("scale_sd", scale_sd), ("amplitude_mm", amplitude_mm), ("extent_mm", extent_mm)):
        if not (np.isfinite(value) and value >= 0):
            raise InputError(f"`{name} >= 0` must hold, but got {name}={value!r}.")
    if int(n_centres) != n_centres or n_centres < 0:
        raise InputError(f"`n_centres` must be a non-negative integer, but got n_centres={n_centres!r}.")
    rng = np.random.default_rng(seed)
    scale = float(np.exp(scale_sd * rng.standard_normal()))
    centre = np.asarray(centre, dtype=np.float64)
    rbf_centres = centre + rng.uniform(-extent_mm, extent_mm, size=(int(n_centres), 3))
    direction = rng.standard_normal((int(n_centres), 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    return Warp(
        scale=scale, centre=centre, rbf_centres=rbf_centres, rbf_weights=amplitude_mm * direction, width_mm=width_mm
    )


def apply_to_mesh(vertices: ArrayLike, faces: ArrayLike, warp: Warp) -> np.ndarray:
    """Warped vertices, array of shape (n, 3), mm; the faces of shape (m, 3) and their winding are unchanged."""
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise MeshError(f"`vertices` must have shape (n, 3), but got shape {v.shape}.")
    if not np.isfinite(v).all():
        bad = np.flatnonzero(~np.isfinite(v).all(axis=1))
        raise MeshError(f"`vertices` must be finite, but vertex {bad[0]} is {v[bad[0]].tolist()}.")
    f = np.asarray(faces)
    if f.ndim != 2 or f.shape[1] != 3 or not np.issubdtype(f.dtype, np.integer):
        raise MeshError(f"`faces` must be integers of shape (m, 3), but got shape {f.shape} of {f.dtype}.")
    if len(v) == 0 or len(f) == 0:
        raise MeshError(f"a mesh must have vertices and faces, but got {len(v)} vertices and {len(f)} faces.")
    if f.min() < 0 or f.max() >= len(v):
        raise MeshError(f"`faces` must index vertices 0..{len(v) - 1}, but got indices {f.min()}..{f.max()}.")
    return warp.apply(v)
