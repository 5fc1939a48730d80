"""The 27 ligament design variables (preprint Table 2): the one owner.

Order: for the eleven ligaments of Table 2, in its order, the stiffness
(N/mm) and reference strain (dimensionless, l_ref / l0) of each (22), then the
injury scalars of SLIL_v, SLIL_p, SLIL_d, RSC, LRL (5).

Normalized action a in [-1, 1]^27 ↔ physical value:
    material = mean + 3·SD·a           (Table 2; reference strain 1.0 ± 0.1)
    injury   = a                       (a < 0: complete tear; population: +1)
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from wrist_env.errors import DesignError
from wrist_env.ligaments import (
    FIXED_LIGAMENTS,
    FIXED_REFERENCE_STRAIN,
    INJURABLE,
    LIGAMENT_NAMES,
    LIGAMENTS,
)

if TYPE_CHECKING:
    from pathlib import Path

__all__ = [
    "N_LIGAMENTS",
    "N_MATERIAL",
    "N_DESIGN",
    "REFERENCE_STRAIN_MEAN",
    "REFERENCE_STRAIN_SD",
    "SPAN_SD",
    "NAMES",
    "INTACT_INJURY",
    "MEAN",
    "SD",
    "Design",
    "read_json",
    "check_action",
    "from_action",
    "from_actions",
    "to_action",
    "split_variables",
    "full_action",
    "population",
    "ligament_arrays",
]


N_LIGAMENTS = len(LIGAMENTS)
N_MATERIAL = 2 * N_LIGAMENTS
N_DESIGN = N_MATERIAL + len(INJURABLE)
REFERENCE_STRAIN_MEAN = 1.0
REFERENCE_STRAIN_SD = 0.1
SPAN_SD = 3.0  # the action's ±1 spans ±3 SD

NAMES = tuple(
    [f"{n}.stiffness" for n in LIGAMENT_NAMES]
    + [f"{n}.reference_strain" for n in LIGAMENT_NAMES]
    + [f"{n}.injury" for n in INJURABLE]
)
"""Variable names in vector order: 11 stiffnesses, 11 reference strains, 5 injury scalars."""
INTACT_INJURY = {name: 1.0 for name in NAMES[N_MATERIAL:]}
"""Normalized injury scalars of intact ligaments: what calibration freezes."""

MEAN = np.concatenate(
    [[l.stiffness_mean for l in LIGAMENTS], np.full(N_LIGAMENTS, REFERENCE_STRAIN_MEAN), np.ones(len(INJURABLE))]
)
SD = np.concatenate(
    [[l.stiffness_sd for l in LIGAMENTS], np.full(N_LIGAMENTS, REFERENCE_STRAIN_SD), np.full(len(INJURABLE), np.nan)]
)
for _a in (MEAN, SD):
    _a.setflags(write=False)


@dataclass(frozen=True)
class Design:
    """A design in physical units: the 27 ligament variables of the preprint's Table 2 for one wrist.

    The fields are frozen copies (read-only arrays), checked when the design is made, so a design that
    exists is one the solver can run.

    Parameters
    ----------
    stiffness : array_like of shape (n_ligaments,)
        Each ligament's stiffness, N/mm, in Table 2 order (`LIGAMENT_NAMES`, n_ligaments = 11).
    reference_strain : array_like of shape (n_ligaments,)
        Each ligament's reference strain l_ref / l0, dimensionless: above 1 the ligament is taut in
        the neutral pose, below 1 slack.
    injury : array_like of shape (n_injurable,)
        The injury scalars of `INJURABLE` (SLIL_v, SLIL_p, SLIL_d, RSC, LRL; n_injurable = 5): below 0
        a complete tear, +1 intact.

    Raises
    ------
    DesignError
        A field of another shape, a value that is not finite, or a stiffness or reference strain ≤ 0
        (the message names the field and its values).

    See Also
    --------
    from_action : the design of a normalized action in [-1, 1]^27 (what the environments take).
    population : Table 2's population means, intact.

    Examples
    --------
    >>> import numpy as np
    >>> from wrist_env import design
    >>> d = design.population()
    >>> d.stiffness.shape, d.injury.shape
    ((11,), (5,))
    >>> design.from_action(np.zeros(27)).as_dict()["SLIL_d.stiffness"]  # N/mm: the action's centre is the mean
    79.0
    """

    stiffness: np.ndarray
    reference_strain: np.ndarray
    injury: np.ndarray

    def __post_init__(self):
        for name, size in (("stiffness", N_LIGAMENTS), ("reference_strain", N_LIGAMENTS), ("injury", len(INJURABLE))):
            arr = np.array(getattr(self, name), dtype=np.float64)
            if arr.shape != (size,):
                raise DesignError(f"`{name}` must have shape ({size},), but got {arr.shape}.")
            if not np.all(np.isfinite(arr)):
                raise DesignError(f"`{name}` must be finite, but got {arr.tolist()}.")
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        if np.any(self.stiffness <= 0):
            raise DesignError(f"stiffness must be > 0 N/mm, but got {self.stiffness.tolist()}.")
        if np.any(self.reference_strain <= 0):
            raise DesignError(f"reference_strain must be > 0, but got {self.reference_strain.tolist()}.")

    @property
    def vector(self) -> np.ndarray:
        """The 27 physical values in `NAMES` order."""
        return np.concatenate([self.stiffness, self.reference_strain, self.injury])

    @property
    def torn(self) -> np.ndarray:
        """Bool array of shape (11,): which ligaments are torn (Table 2 order)."""
        out = np.zeros(N_LIGAMENTS, bool)
        out[[LIGAMENT_NAMES.index(n) for n in INJURABLE]] = self.injury < 0
        return out

    @classmethod
    def from_vector(cls, values: ArrayLike) -> "Design":
        """From the 27 physical values in `NAMES` order."""
        v = np.asarray(values, dtype=np.float64)
        if v.shape != (N_DESIGN,):
            raise DesignError(f"a design vector must have shape ({N_DESIGN},), but got {v.shape}.")
        return cls(v[:N_LIGAMENTS], v[N_LIGAMENTS:N_MATERIAL], v[N_MATERIAL:])

    def as_dict(self) -> dict:
        """JSON-able {name: value} in `NAMES` order."""
        return {n: float(x) for n, x in zip(NAMES, self.vector)}

    @classmethod
    def from_dict(cls, data: dict) -> "Design":
        """From {name: value} in physical units, exactly the 27 `NAMES`, each a JSON number; `DesignError` if
        `data` is not a mapping (None, a list)."""
        if not isinstance(data, Mapping):
            raise DesignError(
                f"a design is a mapping of the 27 variables of `design.NAMES` to numbers, but got {type(data).__name__}"
                f"{'' if data is None else f' {str(data)[:80]}'}."
            )
        missing = [n for n in NAMES if n not in data]
        if missing:
            raise DesignError(f"design is missing variables {missing}.")
        unknown = [k for k in data if k not in NAMES]
        if unknown:
            raise DesignError(f"design variables must be among the 27 of `design.NAMES`, but got {unknown}.")
        not_numbers = {n: data[n] for n in NAMES if isinstance(data[n], bool) or not isinstance(data[n], numbers.Real)}
        if not_numbers:
            raise DesignError(f"design variables must be numbers, but got {not_numbers}.")
        return cls.from_vector([data[n] for n in NAMES])


def read_json(path: str | Path) -> Design:
    """A Design from a JSON file.

    Parameters
    ----------
    path : str or Path
        A JSON file of {name: value} in physical units (`NAMES`), or of an object whose "design" is one (a
        calibration's `--json` output).

    Returns
    -------
    Design
        The design; a `DesignError` naming the file otherwise.
    """
    import json
    from pathlib import Path

    path = Path(path)
    try:
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DesignError(f"{path}: not a readable JSON file ({type(exc).__name__}: {exc})") from None
    if isinstance(data, dict) and isinstance(data.get("design"), dict):
        data = data["design"]
    if not isinstance(data, dict):
        raise DesignError(f"{path}: expected a JSON object of design variables, but got {type(data).__name__}")
    try:
        return Design.from_dict(data)
    except DesignError as exc:
        raise DesignError(f"{path}: {exc}") from None


def check_action(action: ArrayLike) -> np.ndarray:
    """The action, checked: a DesignError naming the offending entries unless finite and in [-1, 1].

    Parameters
    ----------
    action : array_like, shape (27,)
        A normalized action, real numbers.

    Returns
    -------
    np.ndarray, shape (27,)
        The action as float64, in [-1, 1].
    """
    raw = np.asarray(action)
    if not (np.issubdtype(raw.dtype, np.floating) or np.issubdtype(raw.dtype, np.integer)):
        raise DesignError(f"an action must be real numbers, but got dtype {raw.dtype}.")
    a = raw.astype(np.float64)
    if a.shape != (N_DESIGN,):
        raise DesignError(f"an action must have shape ({N_DESIGN},), but got {a.shape}.")
    bad = ~np.isfinite(a) | (np.abs(a) > 1.0 + 1e-9)
    if bad.any():
        detail = ", ".join(f"{NAMES[i]}={float(a[i])!r}" for i in np.flatnonzero(bad))
        raise DesignError(f"actions must be finite and in [-1, 1], but got {detail}.")
    return np.clip(a, -1.0, 1.0)


def from_action(action: ArrayLike) -> Design:
    """Physical design of a normalized action in [-1, 1]^27.

    Parameters
    ----------
    action : array_like, shape (27,)
        The normalized action (`check_action`).

    Returns
    -------
    Design
        Materials mean + 3·SD·a, injury scalars a (the module docstring).
    """
    a = check_action(action)
    values = MEAN + SPAN_SD * np.nan_to_num(SD) * a
    values[N_MATERIAL:] = a[N_MATERIAL:]
    return Design.from_vector(values)


def from_actions(actions: ArrayLike) -> list[Design]:
    """Physical designs of a batch of normalized actions in [-1, 1]; a DesignError names the row.

    Parameters
    ----------
    actions : array_like, shape (n, 27)
        The actions; an empty batch, shape (0, 27) (or an empty list), gives no designs; another shape is
        a DesignError.

    Returns
    -------
    list of Design
        One design per row (`from_action`).
    """
    raw = np.asarray(actions)
    if raw.shape == (0,):
        return []
    if raw.ndim != 2 or raw.shape[1] != N_DESIGN:
        raise DesignError(f"a batch of actions must have shape (n, {N_DESIGN}), but got {raw.shape}.")
    designs = []
    for row, action in enumerate(raw):
        try:
            designs.append(from_action(action))
        except DesignError as e:
            raise DesignError(f"row {row} of the actions: {e}") from None
    return designs


def to_action(design: Design) -> np.ndarray:
    """Normalized action of a physical design (injury scalars clipped to [-1, 1]).

    Parameters
    ----------
    design : Design
        The physical design: materials in N/mm and l_ref / l0, injury scalars.

    Returns
    -------
    np.ndarray, shape (27,)
        The action (the inverse of `from_action`).
    """
    v = design.vector
    a = np.empty(N_DESIGN)
    a[:N_MATERIAL] = (v[:N_MATERIAL] - MEAN[:N_MATERIAL]) / (SPAN_SD * SD[:N_MATERIAL])
    a[N_MATERIAL:] = np.clip(v[N_MATERIAL:], -1.0, 1.0)
    return a


def split_variables(frozen: dict | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The free and the frozen design variables.

    Parameters
    ----------
    frozen : dict, optional
        {variable name (`NAMES`) or index: normalized value in [-1, 1]}; default the five injury scalars
        at +1 (ligaments intact), as calibration does.

    Returns
    -------
    free_index, frozen_index : np.ndarray
        The indices, sorted, of the free and of the frozen variables among the 27.
    frozen_value : np.ndarray
        The frozen variables' normalized values, in `frozen_index` order.
    """
    frozen = INTACT_INJURY if frozen is None else frozen
    index = {(NAMES.index(k) if isinstance(k, str) else int(k)): float(v) for k, v in frozen.items()}
    frozen_index = np.array(sorted(index), dtype=np.int64)
    free_index = np.setdiff1d(np.arange(N_DESIGN), frozen_index)
    return free_index, frozen_index, np.array([index[i] for i in frozen_index])


def full_action(free: ArrayLike, frozen: dict | None = None, dtype: DTypeLike = np.float64) -> np.ndarray:
    """The 27-variable action(s) of the free variables' values with the frozen ones filled in.

    By default the 22 materials → 27 with the injury scalars intact.

    Parameters
    ----------
    free : array_like, shape (..., n_free)
        The free variables' normalized values.
    frozen : dict, optional
        The frozen variables (see `split_variables`).
    dtype : data-type, default np.float64
        The result's dtype.

    Returns
    -------
    np.ndarray, shape (..., 27)
        The actions.
    """
    free_index, frozen_index, frozen_value = split_variables(frozen)
    free = np.asarray(free)
    full = np.empty(free.shape[:-1] + (N_DESIGN,), dtype=dtype)
    full[..., free_index] = free
    full[..., frozen_index] = frozen_value
    return full


def population() -> Design:
    """Table 2 means, all ligaments intact.

    Returns
    -------
    Design
        The population design.
    """
    return Design.from_vector(MEAN)


def ligament_arrays(design: Design) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stiffness, reference strain and torn of every ligament, in `ALL_LIGAMENT_NAMES` order.

    Parameters
    ----------
    design : Design
        The design whose 11 ligaments are listed first; its torn ones are those with injury < 0.

    Returns
    -------
    stiffness, reference_strain, torn : np.ndarray, shape (n_bundles,)
        N/mm, dimensionless and bool: the design's, then the fixed ligaments' (never torn).
    """
    n = len(FIXED_LIGAMENTS)
    return (
        np.concatenate([design.stiffness, [lig.stiffness_mean for lig in FIXED_LIGAMENTS]]),
        np.concatenate([design.reference_strain, np.full(n, FIXED_REFERENCE_STRAIN)]),
        np.concatenate([design.torn, np.zeros(n, bool)]),
    )
