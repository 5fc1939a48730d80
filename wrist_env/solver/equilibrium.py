"""A quasi-static Newton reference: the equilibrium nearest each frame of an explicit run.

With the capitate where the frame put it, solves net force = 0 on the free
bodies (scaphoid and lunate in 6 DOF, the capitate's translations under the
loaded driver) and on the RSC membrane's free nodes, by SciPy's
Levenberg–Marquardt (`least_squares`, finite-difference Jacobian), starting
from the explicit answer. No masses, damping or time step enter: only the
force kernels the explicit solver uses. How far the explicit answer is from
this equilibrium is the explicit solver's error (`experiments/verification/solver_accuracy.py`).
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.optimize import least_squares

from wrist_env.design import Design
from wrist_env.model import CAPITATE, FREE, Model
from wrist_env.solver import arrays, preconditioner, step
from wrist_env.solver.rigid import LEVER_MM, pose_state, pose_translation, rotate_in_place
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import prepare, stiffness
from wrist_env.solver.tangent import tangent

JACOBIAN_STEP = 1e-6  # finite-difference step of the Jacobian (rad, mm)
MAX_EVALUATIONS = 60  # residual evaluations per frame (each with a Jacobian): where contact stalls it, stop

Start = namedtuple("Start", ["R", "x", "nodes", "free_nodes"])
"""The state the unknowns move (`moved_state`): rotations (n_bodies, 3, 3), centres of mass (n_bodies, 3) mm,
RSC membrane nodes (n_nodes, 3) mm, and the indices of the membrane's free nodes (n_free,) int64."""


@njit(cache=True, error_model="numpy")
def moved_state(q, start, loaded):
    """Rotations, centres of mass (mm) and membrane nodes (mm) of the state `start` (`Start`) moved by
    the unknowns q: rotation vectors (rad) and shifts (mm) of the free bodies (`model.FREE`), the capitate's
    shift if `loaded`, the free nodes' (start.free_nodes) shifts (mm)."""
    R = start.R.copy()
    x = start.x.copy()
    nodes = start.nodes.copy()
    free_nodes = start.free_nodes
    k = 0
    for b in FREE:
        rotate_in_place(R[b], q[k], q[k + 1], q[k + 2])
        for i in range(3):
            x[b, i] += q[k + 3 + i]
        k += 6
    if loaded:
        for i in range(3):
            x[CAPITATE, i] += q[k + i]
        k += 3
    for n in free_nodes:
        for i in range(3):
            nodes[n, i] += q[k + i]
        k += 3
    return R, x, nodes


@njit(cache=True, error_model="numpy")
def _residual(q, start, system, stiffness, load, out):
    """Net forces (N) and moments / LEVER_MM (N) on the unknowns (`moved_state`) at the state `start`
    (`Start`) moved by q, of `system` under `stiffness` and the driver's `load` (`step.Load`); into out."""
    loaded = system.settings.driver == arrays.LOADED
    free_nodes = start.free_nodes
    R, x, nodes = moved_state(q, start, loaded)
    n_bones = R.shape[0]
    state = step.State(R, x, np.zeros((n_bones, 3)), np.zeros((n_bones, 3)), nodes, np.zeros_like(nodes))
    work = step.new_work(system.grids, nodes)
    step.net_forces(state, work, system, stiffness, load, True, True, system.settings.smooth_normals)
    F, T, node_force = work.F, work.T, work.node_force
    k = 0
    for b in FREE:
        for i in range(3):
            out[k + i] = F[b, i]
            out[k + 3 + i] = T[b, i] / LEVER_MM
        k += 6
    if loaded:
        for i in range(3):
            out[k + i] = F[CAPITATE, i]
        k += 3
    for n in free_nodes:
        for i in range(3):
            out[k + i] = node_force[n, i]
        k += 3
    return out


@njit(cache=True, error_model="numpy")
def _jacobian(q, start, system, stiffness, load, step):
    """Central-difference Jacobian of `_residual` (n, n) at `start` (`Start`) with steps `step` (rad or mm)."""
    n = q.shape[0]
    J = np.empty((n, n))
    plus = np.empty(n)
    minus = np.empty(n)
    for j in range(n):
        qj = q[j]
        q[j] = qj + step
        _residual(q, start, system, stiffness, load, plus)
        q[j] = qj - step
        _residual(q, start, system, stiffness, load, minus)
        q[j] = qj
        for i in range(n):
            J[i, j] = (plus[i] - minus[i]) / (2.0 * step)
    return J


@dataclass(frozen=True)
class Equilibrium:
    """The equilibria nearest an explicit run's frames.

    poses (n_frames, n_bodies, 4, 4): neutral → frame transforms at equilibrium, RCS mm.
    residual (n_frames, 2): largest net force (N) and moment (N·mm) left on the free bones.
    distance (n_frames, 2): largest centre-of-mass distance (mm) and rotation (deg) of a moving
        bone (the free bodies and the capitate) between the explicit answer and the equilibrium.
    """

    poses: np.ndarray
    residual: np.ndarray
    distance: np.ndarray


def distance(a: np.ndarray, b: np.ndarray, com0: np.ndarray) -> np.ndarray:
    """Per frame, the largest centre-of-mass distance (mm) and rotation (deg) of a moving bone
    (the free bodies and the capitate) between two pose arrays (n_frames, n_bodies, 4, 4); shape (n_frames, 2)."""
    out = np.zeros((len(a), 2))
    for k in FREE + (CAPITATE,):
        ca = np.einsum("fij,j->fi", a[:, k, :3, :3], com0[k]) + a[:, k, :3, 3]
        cb = np.einsum("fij,j->fi", b[:, k, :3, :3], com0[k]) + b[:, k, :3, 3]
        cos = (np.einsum("fij,fij->f", a[:, k, :3, :3], b[:, k, :3, :3]) - 1.0) / 2.0
        out[:, 0] = np.maximum(out[:, 0], np.linalg.norm(ca - cb, axis=1))
        out[:, 1] = np.maximum(out[:, 1], np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    return out


def _unknowns(model: Model, driver) -> tuple[np.ndarray, int]:
    """The membrane's free nodes and the number of unknowns (`moved_state`)."""
    free_nodes = np.flatnonzero(np.asarray(model.membrane_bone) < 0).astype(np.int64)
    return free_nodes, 6 * len(FREE) + (3 if driver.mode == arrays.LOADED else 0) + 3 * len(free_nodes)


def _frame_args(p, design_stiffness, free_nodes, driver, result, f: int) -> tuple:
    """`_residual`'s arguments after q for frame f of `result`: its `Start`, the System, the design's
    `step.Stiffness` and the driver's `step.Load`."""
    R0, x0 = pose_state(result.poses[f], p.bodies.com0)
    nodes0 = np.ascontiguousarray(result.membrane_nodes[f])
    return Start(R0, x0, nodes0, free_nodes), p.system, design_stiffness, driver.kernel_load(f)


def nearest(model: Model, design: Design, driver, result, settings: SolverSettings | None = None) -> Equilibrium:
    """The equilibrium nearest each frame of `result` (a successful `simulate(model, design, driver)`)."""
    if not result.ok:
        raise ValueError(f"the run failed ({result.message}); there is no state to start from")
    p = prepare(model, settings, driver.mode)
    design_stiffness = stiffness(p, design)
    free_nodes, n_unknown = _unknowns(model, driver)
    loaded = driver.mode == arrays.LOADED
    com0 = model.com
    poses = result.poses.copy()
    residual = np.zeros((driver.n_frames, 2))
    out = np.zeros(n_unknown)
    for f in range(driver.n_frames):
        args = _frame_args(p, design_stiffness, free_nodes, driver, result, f)

        def fun(q):
            return _residual(q, *args, out).copy()

        def jac(q):
            return _jacobian(q.copy(), *args, JACOBIAN_STEP)

        q = least_squares(
            fun, np.zeros(n_unknown), jac=jac, method="lm", xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=MAX_EVALUATIONS
        ).x
        r = fun(q)
        R, x, _ = moved_state(q, args[0], loaded)
        poses[f, :, :3, :3] = R
        poses[f, :, :3, 3] = pose_translation(R, x, com0)
        residual[f] = (
            max(np.linalg.norm(r[0:3]), np.linalg.norm(r[6:9])),
            LEVER_MM * max(np.linalg.norm(r[3:6]), np.linalg.norm(r[9:12])),
        )
    return Equilibrium(poses, residual, distance(result.poses, poses, com0))


@dataclass(frozen=True)
class Tangent:
    """The free bones' tangent stiffness at one frame of an explicit run, the RSC membrane's free nodes
    condensed out (they follow quasi-statically).

    Coordinates, per free bone (scaphoid, lunate): shift (mm, world) then rotation (rad, world);
    the capitate's shift after them under the loaded driver. stiffness (n, n): N/mm, N/rad and
    N·mm/rad, symmetrized; mass (n, n): the explicit solver's (mass-scaled) mass (t) and inertia
    (t·mm²) in the same coordinates. `frequencies` solves K u = ω² M u.
    """

    stiffness: np.ndarray
    mass: np.ndarray
    asymmetry: float
    """‖K − Kᵀ‖ / ‖K‖ of the unsymmetrized condensed stiffness (a conservative system's is 0)."""
    membrane: np.ndarray
    """The membrane's free nodes' own stiffness (3F, 3F) N/mm, the bones held (symmetrized)."""

    def frequencies(self) -> np.ndarray:
        """Natural angular frequencies (rad/s) of the linearized free bones, ascending (NaN where ω² < 0)."""
        from scipy.linalg import eigh

        w2 = eigh(self.stiffness, self.mass, eigvals_only=True)
        return np.sqrt(np.where(w2 >= 0.0, w2, np.nan))


def tangent_stiffness(
    model: Model, design: Design, driver, result, frame: int, settings: SolverSettings | None = None
) -> Tangent:
    """`Tangent` stiffness of the free bones at `frame` of `result` (a successful `simulate(model, design, driver)`):
    central differences of the force kernels (`JACOBIAN_STEP`), no time step or damping."""
    if not result.ok:
        raise ValueError(f"the run failed ({result.message}); there is no state to linearize")
    p = prepare(model, settings, driver.mode)
    free_nodes, n_unknown = _unknowns(model, driver)
    args = _frame_args(p, stiffness(p, design), free_nodes, driver, result, frame)
    J = _jacobian(np.zeros(n_unknown), *args, JACOBIAN_STEP)
    n_bones = n_unknown - 3 * len(free_nodes)
    # unknowns per bone are (rotation, shift) and residuals (force, moment / LEVER_MM): reorder to
    # (shift, rotation) against (force, moment) so that K = −∂(force, moment)/∂(shift, rotation)
    order = np.arange(n_unknown)
    rows = np.ones(n_unknown)
    for k in range(len(FREE)):
        order[6 * k : 6 * k + 6] = np.r_[6 * k + 3 : 6 * k + 6, 6 * k : 6 * k + 3]
        rows[6 * k + 3 : 6 * k + 6] = LEVER_MM
    K = -(J * rows[:, None])[:, order]
    bones, nodes = slice(0, n_bones), slice(n_bones, n_unknown)
    condensed = K[bones, bones]
    if len(free_nodes):  # slack connectors leave nodes without stiffness: pseudo-inverse
        condensed = condensed - K[bones, nodes] @ np.linalg.pinv(K[nodes, nodes], rcond=1e-9) @ K[nodes, bones]
    R0 = args[0].R
    mass = np.zeros((n_bones, n_bones))
    for k, b in enumerate(FREE):
        mass[6 * k : 6 * k + 3, 6 * k : 6 * k + 3] = p.bodies.mass[b] * np.eye(3)
        mass[6 * k + 3 : 6 * k + 6, 6 * k + 3 : 6 * k + 6] = R0[b] @ p.bodies.inertia[b] @ R0[b].T
    n_free = 6 * len(FREE)
    if n_bones > n_free:
        mass[n_free:, n_free:] = p.bodies.mass[CAPITATE] * np.eye(3)
    asymmetry = float(np.linalg.norm(condensed - condensed.T) / np.linalg.norm(condensed))
    membrane = K[nodes, nodes]
    return Tangent(0.5 * (condensed + condensed.T), mass, asymmetry, 0.5 * (membrane + membrane.T))


@dataclass(frozen=True)
class BlockMass:
    """The explicit solver's block mass at one frame of a run (`preconditioner`), in `Tangent`'s coordinates.

    stiffness (n, n): the Gauss–Newton tangent the mass is built from (N/mm, N/rad, N·mm/rad); mass (n, n):
    the block-diagonal mass (t, t·mm, t·mm²) at settings.dt_s."""

    stiffness: np.ndarray
    mass: np.ndarray


def block_mass(
    model: Model, design: Design, driver, result, frame: int, settings: SolverSettings | None = None
) -> BlockMass:
    """The `BlockMass` the explicit solver would build at `frame` of `result` (a successful `simulate`)
    under `settings` (their block_* fields; the block mass need not be on)."""
    if not result.ok:
        raise ValueError(f"the run failed ({result.message}); there is no state to linearize")
    p = prepare(model, settings, driver.mode)
    free_nodes, n_unknown = _unknowns(model, driver)
    st = stiffness(p, design)
    R0, x0, nodes0, _ = _frame_args(p, st, free_nodes, driver, result, frame)[0]
    n_bones = n_unknown - 3 * len(free_nodes)
    g = p.grids
    state = step.State(R0.copy(), x0.copy(), np.zeros_like(x0), np.zeros_like(x0), nodes0.copy(), np.zeros_like(nodes0))
    work = step.new_work(g, nodes0)
    load = driver.kernel_load(frame)
    step.net_forces(state, work, p.system, st, load, True, True, p.settings.smooth_normals)
    m = preconditioner.metric()
    tangent(state, p.system, st, work, m, p.settings.smooth_normals)
    preconditioner.block_mass(state.R, p.bodies, p.settings, m)
    return BlockMass(m.stiffness[:n_bones, :n_bones].copy(), m.mass[:n_bones, :n_bones].copy())
