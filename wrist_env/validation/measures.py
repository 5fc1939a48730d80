"""What `validate` measures on a run: slopes, the SL gap, load shares, the radial column's and the hamate's turns."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable

import numpy as np
from numpy.typing import ArrayLike

from wrist_env import design as design_mod
from wrist_env.model import BONES, CAPITATE, MIDCARPAL, Model
from wrist_env.solver.outputs import articulation_forces


def rotation_from_capitate_deg(poses: np.ndarray, body: int) -> np.ndarray:
    """The rotation (deg, per frame) of `body` relative to the capitate over a run's poses (n_frames, n_bodies, 4, 4)."""
    relative = np.einsum("fij,fkj->fik", poses[:, body, :3, :3], poses[:, CAPITATE, :3, :3])
    cos = np.clip((np.trace(relative, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    return np.degrees(np.arccos(cos))


def largest_rotation_deg(poses: np.ndarray, body: int) -> float:
    """The largest rotation (deg) of `body` relative to the capitate over a run's poses.

    The validation's measure of the distal row's rigidity: the radial column (`model.TRAPEZIUM`) and the
    hamate each turn < 3 deg from the capitate (Akhbari 2019, J Orthop Res 37:2661).

    Parameters
    ----------
    poses : ndarray, shape (n_frames, n_bodies, 4, 4)
        The bodies' poses per frame (neutral → frame; mm).
    body : int
        The body's index (`model.BONES`).

    Returns
    -------
    float
        Its largest rotation relative to the capitate over the frames, deg.
    """
    return float(rotation_from_capitate_deg(poses, body).max())


def slope(x: ArrayLike, y: ArrayLike) -> float:
    """Least-squares slope of y against x over the finite pairs; NaN if x does not vary.

    Parameters
    ----------
    x, y : array_like, shape (n,)
        The paired values; a pair where either is not finite is left out.

    Returns
    -------
    float
        The slope, in y's unit per x's; NaN with fewer than two finite pairs or a constant x.

    Examples
    --------
    >>> slope([0.0, 1.0, 2.0, float("nan")], [1.0, 3.0, 5.0, 0.0])
    2.0
    """
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    if len(x) < 2 or np.ptp(x) == 0:
        return float("nan")
    dx = x - x.mean()
    return float(dx @ (y - y.mean()) / (dx @ dx))


def surface_gap_mm(
    a_mesh: tuple[ArrayLike, ArrayLike], b_mesh: tuple[ArrayLike, ArrayLike], a_poses: ArrayLike, b_poses: ArrayLike
) -> np.ndarray:
    """Minimum distance (mm) between two posed triangle surfaces at each frame.

    Each surface's vertices are taken into the other's neutral frame and their closest points on the
    other's triangles found (libigl's point–mesh distance); the smaller of both directions.

    Parameters
    ----------
    a_mesh, b_mesh : tuple of (array_like, array_like)
        (vertices of shape (n, 3), mm; faces of shape (m, 3), vertex indices) at the neutral pose.
    a_poses, b_poses : array_like, shape (n_frames, 4, 4)
        Each surface's pose per frame, neutral → frame (mm).

    Returns
    -------
    ndarray, shape (n_frames,)
        The gap, mm: 0 where the surfaces touch; NaN where a pose is not finite.
    """
    import igl

    meshes = [
        (np.ascontiguousarray(v, dtype=np.float64), np.ascontiguousarray(f, dtype=np.int64))
        for v, f in (a_mesh, b_mesh)
    ]
    a_poses, b_poses = np.asarray(a_poses, dtype=np.float64), np.asarray(b_poses, dtype=np.float64)
    out = np.full(len(a_poses), np.nan)
    for k, (Ta, Tb) in enumerate(zip(a_poses, b_poses)):
        if not (np.isfinite(Ta).all() and np.isfinite(Tb).all()):
            continue
        best = np.inf
        for (pv, _), (qv, qf), rel in (
            (meshes[0], meshes[1], np.linalg.solve(Tb, Ta)),
            (meshes[1], meshes[0], np.linalg.solve(Ta, Tb)),
        ):
            points = np.ascontiguousarray(pv @ rel[:3, :3].T + rel[:3, 3])
            sq, _, _ = igl.point_mesh_squared_distance(points, qv, qf)
            best = min(best, float(np.sqrt(sq.min())))
        out[k] = best
    return out


def sl_gap_mm(model: Model, poses: np.ndarray) -> np.ndarray:
    """Scapholunate gap (mm) per frame of a Result's poses: bone surface to bone surface.

    Parameters
    ----------
    model : Model
        The participant's model (its scaphoid and lunate meshes).
    poses : ndarray, shape (n_frames, n_bodies, 4, 4)
        The bodies' poses per frame (a `Result`'s ``poses``; mm).

    Returns
    -------
    ndarray, shape (n_frames,)
        The gap per frame, mm (`surface_gap_mm`).
    """
    s, l = BONES.index("scaphoid"), BONES.index("lunate")
    return surface_gap_mm(model.part_mesh("scaphoid"), model.part_mesh("lunate"), poses[:, s], poses[:, l])


def with_tears(d: design_mod.Design, names: Iterable[str]) -> design_mod.Design:
    """A copy of the design with the named injurable ligaments torn (injury scalar −1).

    Parameters
    ----------
    d : Design
        The design; not changed.
    names : iterable of str
        Names of injurable ligaments (`design.INJURABLE`).

    Returns
    -------
    Design
        `d` with those ligaments' injury scalars set to −1.

    Raises
    ------
    ValueError
        A name that is not an injurable ligament.
    """
    injury = np.array(d.injury, dtype=np.float64)
    for n in names:
        injury[design_mod.INJURABLE.index(n)] = -1.0
    return dataclasses.replace(d, injury=injury)


def at_angle(angle_deg: ArrayLike, values: ArrayLike, target_deg: float) -> float:
    """`values` at the capitate angle `target_deg`, linear between the sweep's frames (NaN outside).

    Parameters
    ----------
    angle_deg : array_like, shape (n_frames,)
        The capitate's angle per frame of the sweep, deg (any order).
    values : array_like, shape (n_frames,)
        A measure per frame, any unit.
    target_deg : float
        The angle to read the measure at, deg.

    Returns
    -------
    float
        The measure at `target_deg`, linearly interpolated; NaN outside the sweep's angles.

    Examples
    --------
    >>> at_angle([-10.0, 0.0, 10.0], [1.0, 2.0, 4.0], 5.0)
    3.0
    """
    a, v = np.asarray(angle_deg, dtype=np.float64), np.asarray(values, dtype=np.float64)
    order = np.argsort(a)
    a, v = a[order], v[order]
    if not (a[0] <= target_deg <= a[-1]):
        return float("nan")
    return float(np.interp(target_deg, a, v))


def load_shares_pct(model: Model, result) -> dict[str, float]:
    """Load shares (%) at a run's first frame.

    Each midcarpal articulation's share (`model.MIDCARPAL`) of their sum, and "ulnocarpal": the ulnar path's
    of radiocarpal + ulnocarpal.

    Parameters
    ----------
    model : Model
        The participant's model.
    result : Result
        A simulation's result (`solver.simulate`).

    Returns
    -------
    dict of str to float
        ``{articulation: share, %}`` for each of `model.MIDCARPAL` and "ulnocarpal"; NaN for a failed run
        (or where the forces summed over are 0).
    """
    if not result.ok:
        return {name: math.nan for name in (*MIDCARPAL, "ulnocarpal")}
    f = articulation_forces(model, result.poses[0])
    midcarpal = sum(f[name] for name in MIDCARPAL)
    proximal = f["radioscaphoid"] + f["radiolunate"] + f["ulnocarpal"]
    out = {name: 100.0 * f[name] / midcarpal if midcarpal > 0 else math.nan for name in MIDCARPAL}
    out["ulnocarpal"] = 100.0 * f["ulnocarpal"] / proximal if proximal > 0 else math.nan
    return out
