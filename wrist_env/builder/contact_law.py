"""Cartilage contact law: tri-linear pressure–strain fit to Mooney–Rivlin layers (preprint 2.2.2.2).

Cartilage is rigid-rigid: two opposing layers carry contact, not internal
stress. Their compression is modelled as two bonded, compressible
Mooney–Rivlin layers (C10 = 4.1 MPa, C01 = 0.41 MPa, D1 = 0.0475 MPa⁻¹) in
confined compression. Two identical layers in series carry the same stress,
hence the same strain, so the law is written in nominal strain
e = overclosure / (total cartilage thickness of both layers) and one law
serves every local thickness.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import least_squares

from wrist_env.errors import BuildError, InputError

C10_MPA = 4.1
C01_MPA = 0.41
D1_PER_MPA = 0.0475


def mooney_rivlin_confined_pressure(
    strain: ArrayLike, c10: float = C10_MPA, c01: float = C01_MPA, d1: float = D1_PER_MPA
) -> np.ndarray:
    """Nominal compressive stress (MPa, positive in compression) of a confined Mooney–Rivlin layer.

    strain: nominal compressive strain, scalar or array, each < 1 (axial stretch
    λ = 1 − strain, lateral stretches 1). W = C10(Ī1 − 3) + C01(Ī2 − 3) + (J − 1)²/D1
    with isochoric invariants; the stress is −dW/dλ. Returns an array of strain's shape.
    """
    if not (c10 >= 0 and c01 >= 0 and c10 + c01 > 0):
        raise InputError(f"`c10 >= 0`, `c01 >= 0` and `c10 + c01 > 0` must hold, but got ({c10=}, {c01=}).")
    if not d1 > 0:
        raise InputError(f"`d1 > 0` must hold, but got {d1=}.")
    e = np.asarray(strain, dtype=np.float64)
    if not np.isfinite(e).all() or (e >= 1).any():
        bad = e[~(np.isfinite(e) & (e < 1))].ravel()[0]
        raise InputError(f"strain must be finite and < 1 (stretch 1 - strain > 0), but got {bad}.")
    lam = 1.0 - e
    # F = diag(1, 1, λ), J = λ: Ī1 = 2λ^(-2/3) + λ^(4/3), Ī2 = λ^(-4/3) + 2λ^(2/3).
    d_i1 = (4.0 / 3.0) * (lam ** (1.0 / 3.0) - lam ** (-5.0 / 3.0))
    d_i2 = (4.0 / 3.0) * (lam ** (-1.0 / 3.0) - lam ** (-7.0 / 3.0))
    dw_dlam = c10 * d_i1 + c01 * d_i2 + 2.0 * (lam - 1.0) / d1
    return -dw_dlam


@dataclass(frozen=True)
class TrilinearLaw:
    """Tri-linear pressure–strain law, continuous, zero for strain <= 0.

    e1 < e2: strain breakpoints (nominal strain, overclosure / total thickness).
    k1, k2, k3: slopes (MPa per unit strain) on (0, e1], (e1, e2], (e2, ∞).
    """

    e1: float
    e2: float
    k1: float
    k2: float
    k3: float

    def __post_init__(self):
        values = (self.e1, self.e2, self.k1, self.k2, self.k3)
        if not all(np.isfinite(values)):
            raise InputError(f"tri-linear law parameters must be finite, but got {values}.")
        if not 0 < self.e1 < self.e2:
            raise InputError(f"`0 < e1 < e2` must hold, but got (e1={self.e1}, e2={self.e2}).")
        for name in ("k1", "k2", "k3"):
            if not getattr(self, name) > 0:
                raise InputError(f"`{name} > 0` must hold, but got {name}={getattr(self, name)}.")

    def pressure(self, strain: ArrayLike) -> np.ndarray:
        """Contact pressure (MPa) at nominal strain (scalar or array); array of strain's shape."""
        return _trilinear(strain, self.e1, self.e2, self.k1, self.k2, self.k3)

    def as_array(self) -> np.ndarray:
        """Array of shape (5,), float64: [e1, e2, k1, k2, k3] (strain, strain, MPa, MPa, MPa).

        The layout read by the Numba contact kernels (`solver.contact.law_pressure`).
        """
        return np.array([self.e1, self.e2, self.k1, self.k2, self.k3], dtype=np.float64)


@dataclass(frozen=True)
class ContactLawFit:
    """A fitted law and the curve it was fitted to.

    law: the tri-linear law. r2: coefficient of determination of the fit.
    strain: array of shape (n,), the fitted strains. pressure: array of shape (n,),
    MPa, the Mooney–Rivlin pressure at those strains.
    """

    law: TrilinearLaw
    r2: float
    strain: np.ndarray
    pressure: np.ndarray


def _trilinear(strain, e1, e2, k1, k2, k3) -> np.ndarray:
    e = np.asarray(strain, dtype=np.float64)
    p1 = k1 * e1
    p2 = p1 + k2 * (e2 - e1)
    return np.where(e <= 0, 0.0, np.where(e <= e1, k1 * e, np.where(e <= e2, p1 + k2 * (e - e1), p2 + k3 * (e - e2))))


def _law(x, max_strain):
    """(e1, e2, k1, k2, k3) from fit variables (a, b, k1, k2, k3), a, b in (0, 1)."""
    e1 = x[0] * max_strain
    return e1, e1 + x[1] * (max_strain - e1), x[2], x[3], x[4]


def fit_contact_law(
    max_strain: float = 0.35, n: int = 200, c10: float = C10_MPA, c01: float = C01_MPA, d1: float = D1_PER_MPA
) -> ContactLawFit:
    """Least-squares tri-linear fit (slopes > 0) to the confined Mooney–Rivlin curve on [0, max_strain].

    max_strain: largest fitted strain (0 < max_strain < 1). n: number of strains (>= 10).
    """
    if not 0 < max_strain < 1:
        raise InputError(f"`0 < max_strain < 1` must hold, but got {max_strain=}.")
    if not n >= 10:
        raise InputError(f"`n >= 10` must hold, but got {n=}.")
    strain = np.linspace(0.0, max_strain, n)
    target = mooney_rivlin_confined_pressure(strain, c10, c01, d1)
    scale = max(float(np.abs(target).max()), 1e-12)

    def residual(x):
        return (_trilinear(strain, *_law(x, max_strain)) - target) / scale

    # Start from secants over thirds; slopes stay positive through the bounds.
    third = np.interp([max_strain / 3, 2 * max_strain / 3, max_strain], strain, target)
    secants = np.diff(np.concatenate([[0.0], third])) / (max_strain / 3)
    x0 = np.concatenate([[1 / 3, 0.5], np.maximum(secants, 1e-3)])
    tiny = 1e-6
    fit = least_squares(
        residual,
        x0,
        bounds=([tiny, tiny, tiny, tiny, tiny], [1 - tiny, 1 - tiny, np.inf, np.inf, np.inf]),
        x_scale="jac",
    )
    try:
        law = TrilinearLaw(*map(float, _law(fit.x, max_strain)))
    except InputError as err:
        raise BuildError(f"the contact-law fit gave an invalid law: {err}") from err
    ss_res = float(np.sum((law.pressure(strain) - target) ** 2))
    ss_tot = float(np.sum((target - target.mean()) ** 2))
    strain.setflags(write=False)
    target.setflags(write=False)
    return ContactLawFit(law=law, r2=1.0 - ss_res / ss_tot, strain=strain, pressure=target)
