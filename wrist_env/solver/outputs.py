"""Outputs of a simulation for people and files: per-sample pressure maps and JSON-ready frames.

Thin on purpose: pressures come from `forces.sample_pressures` (the solver's
own contact law and grids); everything else is read off a `Result`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from wrist_env.frames import cardan_angles
from wrist_env.ligaments import ALL_LIGAMENT_NAMES
from wrist_env.model import ARTICULATIONS, BODY_PARTS, BONES, PAIR_BONES, PAIRS, ULNA, Model
from wrist_env.solver import arrays, forces
from wrist_env.solver.forces import CONTACT_FIELDS
from wrist_env.solver.rigid import pose_state

if TYPE_CHECKING:
    from wrist_env.solver.simulate import Result


def _state(model: Model, pose_frame):
    """(R (n_bodies, 3, 3), x (n_bodies, 3)) of the kernels from one frame's poses (n_bodies, 4, 4),
    neutral → frame."""
    P = np.asarray(pose_frame, dtype=np.float64)
    if P.shape != (len(BONES), 4, 4):
        raise ValueError(f"pose_frame must have shape ({len(BONES)}, 4, 4), but got {P.shape}")
    return pose_state(P, model.com)


def pressure_map(model: Model, pose_frame: ArrayLike) -> np.ndarray:
    """Contact pressure (MPa) of every contact sample, shape (n_samples,), at one frame's poses
    (n_bodies, 4, 4).

    Samples are in `model.sample_points` order (pair-sorted, `PAIRS`; pair p is
    `model.sample_offsets[p]:model.sample_offsets[p + 1]`); a sample out of
    contact has pressure 0. Note: the kernel reports `Result.contact` from the
    forces of its last explicit step, evaluated before that step moved the bones
    to `Result.poses`, so sums of this map match `Result.contact` to ~1e-3, not exactly.
    """
    R, x = _state(model, pose_frame)
    pressure = np.zeros(len(model.sample_points))
    forces.sample_pressures(
        R,
        x,
        np.ascontiguousarray(model.com, dtype=np.float64),
        arrays.grids(model),
        np.ascontiguousarray(model.contact_law, dtype=np.float64),
        pressure,
    )
    return pressure


def pair_slice(model: Model, pair: str) -> slice:
    """The samples of one articulation (a `PAIRS` name) in `model.sample_points` order."""
    p = PAIRS.index(pair)
    return slice(int(model.sample_offsets[p]), int(model.sample_offsets[p + 1]))


def sample_parts(model: Model, pair: str) -> np.ndarray:
    """Index into `BODY_PARTS` of the pair's sample body of the bone under each of the pair's samples (n,)."""
    from scipy.spatial import cKDTree

    p = PAIRS.index(pair)
    body = PAIR_BONES[p][0]
    v = slice(int(model.vertex_offsets[body]), int(model.vertex_offsets[body + 1]))
    return model.vertex_part[v][cKDTree(model.vertices[v]).query(model.sample_points[pair_slice(model, pair)])[1]]


def articulation_forces(model: Model, pose_frame: ArrayLike) -> dict[str, float]:
    """Contact force (N: pressure integrated over area, as pressure-sensitive film measures it and
    `Result.contact` reports it) through each articulation (`model.ARTICULATIONS`) at one frame's poses
    (n_bodies, 4, 4), from `pressure_map`; "ulnocarpal" sums the pairs that touch the ulna (0 in a model
    without an ulnar load path)."""
    load = pressure_map(model, pose_frame) * model.sample_area
    out = {}
    for name, (pair, parts) in ARTICULATIONS.items():
        body = BONES[PAIR_BONES[PAIRS.index(pair)][0]]
        mine = np.isin(sample_parts(model, pair), [BODY_PARTS[body].index(q) for q in parts])
        out[name] = float(load[pair_slice(model, pair)][mine].sum())
    ulnar = [p for p, bones in zip(PAIRS, PAIR_BONES) if ULNA in bones]
    out["ulnocarpal"] = float(sum(load[pair_slice(model, p)].sum() for p in ulnar))
    return out


def driven_body_load(
    model: Model, design, driver, pose_frame: ArrayLike, membrane_nodes: ArrayLike, frame: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """The net force (3,) N and moment (3,) N·mm, RCS, of every force on the driven capitate body at one
    frame's poses (n_bodies, 4, 4) and RSC membrane nodes (n_nodes, 3) (a `Result`'s `poses[f]`, `membrane_nodes[f]`):
    its contacts, ligaments, the membrane and `driver`'s lines at `frame` (`Driver.kernel_load`), summed
    by the solver's own force kernel (`step.net_forces`), the moment about the capitate's centre of
    mass where the poses put it. The driver holds the opposite: at a loaded driver's equilibrium the
    force is ~0 (its translations are free) and the moment is what the prescribed rotation absorbs
    (about z flexion +, x ulnar deviation +, y pronation +: `cardan_deg`'s senses for a right wrist)."""
    from wrist_env.model import CAPITATE
    from wrist_env.solver import simulate, step

    p = simulate.prepare(model, None, driver.mode)
    R, x = _state(model, pose_frame)
    nodes = np.array(membrane_nodes, dtype=np.float64)
    state = step.State(R, x, np.zeros_like(x), np.zeros_like(x), nodes, np.zeros_like(nodes))
    work = step.new_work(p.grids, nodes)
    load = driver.kernel_load(frame)
    step.net_forces(state, work, p.system, simulate.stiffness(p, design), load, True, True, p.settings.smooth_normals)
    return work.F[CAPITATE].copy(), work.T[CAPITATE].copy()


def cardan_deg(poses: ArrayLike) -> np.ndarray:
    """Cardan Z-X-Y angles (deg, `wrist_env.frames.cardan_angles`) of poses (..., 4, 4) or rotations
    (..., 3, 3): Flex/Ext (about z, flexion +), UlnD/RadD (ulnar +), Pro/Sup; NaN where a pose is not finite."""

    R = np.asarray(poses, dtype=np.float64)[..., :3, :3]
    flat = R.reshape(-1, 3, 3)
    out = np.full((len(flat), 3), np.nan)
    ok = np.isfinite(flat).all(axis=(1, 2))
    if ok.any():
        out[ok] = cardan_angles(flat[ok])
    return out.reshape(R.shape[:-2] + (3,))


def _num(value):
    """A JSON number, or None for NaN/inf."""
    v = float(value)
    return v if math.isfinite(v) else None


def _matrix(m):
    return [[_num(v) for v in row] for row in np.asarray(m)]


def result_to_dict(result: Result, model: Model) -> dict:
    """JSON-ready per-frame outputs of a `Result` (NaN → None; strict JSON with `allow_nan=False`).

    {"status", "ok", "message", "n_frames", "bones", "pairs", "ligaments", "frames": [
      {"frame", "capitate_angle_deg" (driver angle, None for experimental drivers),
       "rotation_deg": {bone: [about z (flexion +), about x, about y]} (Cardan Z-X-Y of the pose),
       "poses": {bone: 4×4 neutral → frame, RCS mm},
       "contact": {pair: {"mean_pressure_mpa", "peak_pressure_mpa", "area_mm2", "force_n"}},
       "ligament_force_n": {ligament: N}, "kinetic_energy_nmm", "internal_energy_nmm",
       "residual": {"force_n", "moment_nmm"}, "steps", "settled"}, ...]}
    """
    n = len(result.poses)
    angles = cardan_deg(result.poses)
    frames = []
    for f in range(n):
        frames.append(
            {
                "frame": f,
                "capitate_angle_deg": _num(result.angle_deg[f]),
                "rotation_deg": {b: [_num(a) for a in angles[f, i]] for i, b in enumerate(BONES)},
                "poses": {b: _matrix(result.poses[f, i]) for i, b in enumerate(BONES)},
                "contact": {
                    p: {field: _num(v) for field, v in zip(CONTACT_FIELDS, c)} for p, c in zip(PAIRS, result.contact[f])
                },
                "ligament_force_n": {name: _num(v) for name, v in zip(ALL_LIGAMENT_NAMES, result.bundle_force[f])},
                "kinetic_energy_nmm": _num(result.energy[f, 0]),
                "internal_energy_nmm": _num(result.energy[f, 1]),
                "residual": {"force_n": _num(result.residual[f, 0]), "moment_nmm": _num(result.residual[f, 1])},
                "steps": int(result.steps[f]),
                "settled": bool(result.settled[f]),
            }
        )
    return {
        "status": int(result.status),
        "ok": bool(result.ok),
        "message": result.message,
        "n_frames": n,
        "bones": list(BONES),
        "pairs": list(PAIRS),
        "ligaments": list(ALL_LIGAMENT_NAMES),
        "frames": frames,
    }
