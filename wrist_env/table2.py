"""The preprint's Table 2 as a distribution: the 22 ligament materials in SD units (z-scores) about the
population means (`design.MEAN`, `design.SD`), and their prior, Table 2's normals truncated (the one owner:
the Monte Carlo sampler, the instances' truths, the calibrators' start points and the likelihood's prior all
draw or weigh with `material_prior`)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from wrist_env.design import MEAN, N_MATERIAL, SD, SPAN_SD, Design
from wrist_env.errors import DesignError

__all__ = ["z_scores", "with_z", "material_prior", "sample_materials"]


def z_scores(design: Design) -> np.ndarray:
    """Material values in Table 2 SD units.

    Parameters
    ----------
    design : Design
        The design whose 22 materials are scored (its injury scalars are not).

    Returns
    -------
    np.ndarray, shape (22,)
        Each material's (value − mean) / SD.
    """
    return (design.vector[:N_MATERIAL] - MEAN[:N_MATERIAL]) / SD[:N_MATERIAL]


def with_z(base: Design, z: ArrayLike) -> Design:
    """A design with its 22 materials at given Table 2 SD units from the mean (the inverse of `z_scores`).

    Parameters
    ----------
    base : Design
        The design whose injury scalars are kept.
    z : array_like, shape (22,)
        The materials' z scores.

    Returns
    -------
    Design
        `base` with its materials at mean + SD·z.
    """
    z = np.asarray(z, dtype=np.float64)
    if z.shape != (N_MATERIAL,):
        raise DesignError(f"z must have shape ({N_MATERIAL},), but got {z.shape}.")
    values = base.vector.copy()
    values[:N_MATERIAL] = MEAN[:N_MATERIAL] + SD[:N_MATERIAL] * z
    return Design.from_vector(values)


def material_prior(truncate_sd: float = SPAN_SD):
    """One material's population prior in SD units (z), as a frozen SciPy distribution.

    The one owner: the Monte Carlo sampler, the instances' truths, the calibrators' start points and the
    likelihood's prior all draw or weigh with it.

    Parameters
    ----------
    truncate_sd : float, default SPAN_SD
        The truncation, ±SD (`SPAN_SD` spans the action box).

    Returns
    -------
    scipy.stats frozen distribution
        Table 2's normal, N(0, 1), truncated at ± `truncate_sd` (frozen).
    """
    from scipy.stats import truncnorm  # here: scipy.stats takes 0.5 s to import

    return truncnorm(-truncate_sd, truncate_sd)


def sample_materials(n: int, seed: int | None, *, truncate_sd: float = SPAN_SD) -> np.ndarray:
    """Normalized material actions drawn from Table 2's normals truncated (`material_prior`).

    Parameters
    ----------
    n : int
        How many.
    seed : int or None
        The seed of `np.random.default_rng`.
    truncate_sd : float, default SPAN_SD
        The truncation, ±SD.

    Returns
    -------
    np.ndarray, shape (n, 22)
        The actions, in [-truncate_sd / SPAN_SD, truncate_sd / SPAN_SD].
    """
    rng = np.random.default_rng(seed)
    z = material_prior(truncate_sd).rvs(size=(n, N_MATERIAL), random_state=rng)
    return z / SPAN_SD
