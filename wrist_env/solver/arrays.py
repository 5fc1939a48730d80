"""Kernel inputs: the one place where a `Model`, a `Design` and settings become arrays.

The kernels take named tuples of contiguous arrays (Numba handles them as
plain records). Nothing here runs in a hot loop.
"""

from __future__ import annotations

import weakref
from collections import namedtuple
from dataclasses import dataclass, replace

import numpy as np

from wrist_env.design import RSC_INDEX, Design, ligament_arrays
from wrist_env.model import BONES, PAIR_BONES, Model
from wrist_env.solver.contact import nodal_normals

Bodies = namedtuple("Bodies", "com0 inv_mass inv_inertia mass inertia")
Grids = namedtuple(
    "Grids",
    "pair_bones sample_offsets points thickness area values offsets shape origin spacing normals pair_centre pair_reach",
)
Fibres = namedtuple("Fibres", "bones origin insertion ligament rest_length")
Membrane = namedtuple(
    "Membrane",
    "connectors kind first_row bone rest scaphoid grid_values grid_offset grid_shape grid_origin grid_spacing rest_length "
    "grid_normals",
)
Settings = namedtuple(
    "Settings",
    "dt settle_steps move_steps ramp_steps min_hold_steps max_hold_steps tolerance force_floor damping rot_damping fibre_damping_s "
    "active_band_mm node_mass membrane_contact_stiffness driver max_disp_mm max_rot_rad fire_alpha0 smooth_normals "
    "block_mass block_courant block_floor block_refresh_steps block_max_move_mm membrane_substeps membrane_substep_damping block_refresh_restart predict predict_ramp_steps",
)
System = namedtuple("System", "bodies grids law fibres membrane settings")
"""A model's physics as the kernels read it and none writes: `Bodies`, contact `Grids`, the contact law
(`model.contact_law`), `Fibres`, the RSC `Membrane` and the solver `Settings`."""

RSC = RSC_INDEX
EXPERIMENTAL, LOADED = 0, 1


@dataclass(frozen=True)
class SolverSettings:
    """Explicit-integration settings (s, mm, N, t).

    dt_s: time step. Each stage ramps the capitate (move_steps to the first
    pose, ramp_steps between frames), then holds it until the free bodies
    are in equilibrium: net force at most max(force_floor_n, tolerance ×
    the largest bundle force) and net moment at most that × 10 mm, after at
    least min_hold_steps and at most max_hold_steps (settling: at most
    settle_steps). damping_per_s: mass-proportional damping of translations
    and rotations; fire_alpha0: FIRE mixing (0 turns FIRE off).
    smooth_normals: contact forces along the grids' nodal gradients
    interpolated trilinearly (continuous), instead of the derivative of the
    trilinear distance (which jumps at cell faces, so no state balances
    exactly: `experiments/verification/solver_accuracy.py`).
    block_mass: one 6×6 mass block per free bone (3×3 for the loaded capitate)
    from the force kernels' tangent (`preconditioner`), rebuilt every
    block_refresh_steps, at each stage and (block_refresh_restart) after each
    FIRE restart; its stiffest mode at dt·ω = block_courant, each bone's soft
    directions floored at block_floor of the stiffest; a bone's step is cut to
    block_max_move_mm (its shift plus rotation × 10 mm).
    membrane_substeps: extra steps of the RSC membrane's free nodes per step,
    the bones held, with mass-proportional damping
    membrane_substep_damping_per_s (`membrane`). predict: start each frame of
    the loaded driver from the secant through the last two frames' equilibria
    (`predictor`), ramping the capitate over predict_ramp_steps instead of
    ramp_steps, where that lowers the residual (the trials' measured poses
    are too noisy to extrapolate: their holds then lock up, measured in the
    README). `preconditioned()` turns these on with the stages they need.
    mass_scale, inertia_scale: mass scaling of the free bones (inertia_scale
    multiplies rotational inertia on top of mass_scale). node_mass_t: the mass
    of the RSC membrane's free nodes, raised per design where its connectors
    are too stiff for dt_s (`node_mass`). active_band_mm: a
    contact sample is looked up every step while it is within this distance
    of contact (a pair's set is refilled once its samples may have moved half
    of it: `forces.contact_forces`).
    """

    dt_s: float = 6e-5
    settle_steps: int = 800
    move_steps: int = 200
    ramp_steps: int = 60
    min_hold_steps: int = 10
    max_hold_steps: int = 1600
    tolerance: float = 0.001
    force_floor_n: float = 0.01
    damping_per_s: float = 100.0
    rot_damping_per_s: float = 100.0
    fibre_damping_s: float = 2e-4
    mass_scale: float = 10.0
    inertia_scale: float = 2.0
    active_band_mm: float = 0.15
    node_mass_t: float = 2e-7
    membrane_contact_stiffness: float = 50.0
    max_disp_mm: float = 15.0
    max_rot_deg: float = 75.0
    fire_alpha0: float = 0.1
    smooth_normals: bool = True
    block_mass: bool = False
    block_courant: float = 0.8
    block_floor: float = 0.1
    block_refresh_steps: int = 10
    block_max_move_mm: float = 0.3
    membrane_substeps: int = 0
    membrane_substep_damping_per_s: float = 2000.0
    block_refresh_restart: bool = True
    predict: bool = False
    predict_ramp_steps: int = 0

    def preconditioned(self) -> "SolverSettings":
        """These settings with the block mass (`preconditioner`), the membrane's nodes subcycled 7
        steps a step (`membrane`) and the secant predictor (`predictor`), and the stages they need:
        ramps of 10 steps, a 60-step move to the first pose (30 lands P1's and P3's 40° flexion on
        another equilibrium), at most 150 settling steps, FIRE's α₀ 0.2, no fibre damping (a viscous
        term in seconds that the block mass's light directions cannot carry: dt·c/m = fibre_damping_s
        / dt_s · block_courant² > 2 at block_courant 1), the mass rebuilt every 20 steps and at each
        stage but not after FIRE's restarts (a rebuild costs ~3 steps; rebuilding at the restarts too
        cost 1.15–1.7× the time for about the same steps). Measured in `experiments/benchmarks/bench_solver.py`
        and the README's solver section."""
        return replace(
            self,
            block_mass=True,
            fibre_damping_s=0.0,
            fire_alpha0=0.2,
            settle_steps=150,
            move_steps=60,
            ramp_steps=10,
            block_refresh_steps=20,
            block_refresh_restart=False,
            membrane_substeps=7,
            predict=True,
        )

    def halved(self) -> "SolverSettings":
        """The same run with half the time step (twice the steps)."""
        return replace(
            self,
            dt_s=self.dt_s / 2,
            settle_steps=2 * self.settle_steps,
            move_steps=2 * self.move_steps,
            ramp_steps=2 * self.ramp_steps,
            min_hold_steps=2 * self.min_hold_steps,
            max_hold_steps=2 * self.max_hold_steps,
        )


SOLVERS = ("default", "preconditioned")
"""The named solver settings: today's defaults, and `SolverSettings.preconditioned` (opt-in, issue 32)."""


def solver_settings(name: str) -> SolverSettings:
    """The settings of a solver in `SOLVERS`."""
    if name not in SOLVERS:
        raise ValueError(f"solver must be one of {SOLVERS}, but got {name!r}")
    return SolverSettings().preconditioned() if name == "preconditioned" else SolverSettings()


def bodies(model: Model, s: SolverSettings) -> Bodies:
    mass = model.mass * s.mass_scale
    inertia = model.inertia * (s.mass_scale * s.inertia_scale)
    inv_mass = np.where(mass > 0, 1.0 / np.where(mass > 0, mass, 1.0), 0.0)
    inv_inertia = np.array([np.linalg.inv(I) if m > 0 else np.zeros((3, 3)) for I, m in zip(inertia, mass)])
    return Bodies(np.ascontiguousarray(model.com), inv_mass, inv_inertia, mass, inertia)


_NORMALS: dict[int, tuple[weakref.ref, np.ndarray]] = {}


def _normals(model: Model) -> np.ndarray:
    """`contact.nodal_normals` of the model's grids, computed once per model object."""
    key = id(model)
    cached = _NORMALS.get(key)
    if cached is not None and cached[0]() is model:
        return cached[1]
    normals = nodal_normals(model.grid_values, model.grid_offsets, model.grid_shape, model.grid_spacing)
    normals.setflags(write=False)
    _NORMALS[key] = (weakref.ref(model, lambda _, key=key: _NORMALS.pop(key, None)), normals)
    return normals


def grids(model: Model, smooth_normals: bool = False) -> Grids:
    """The contact arrays; with `smooth_normals` the grids' nodal normals
    (`contact.nodal_normals`, (n, 4)) too, else an empty (0, 4)."""
    normals = _normals(model) if smooth_normals else np.zeros((0, 4), np.int8)
    offsets = np.asarray(model.sample_offsets)
    centre = np.zeros((len(PAIR_BONES), 3))
    reach = np.zeros(len(PAIR_BONES))
    for p in range(len(PAIR_BONES)):
        points = np.asarray(model.sample_points[offsets[p] : offsets[p + 1]], np.float64)
        if len(points):
            centre[p] = points.mean(axis=0)
            reach[p] = np.linalg.norm(points - centre[p], axis=1).max()
    return Grids(
        np.ascontiguousarray(PAIR_BONES, dtype=np.int64),
        np.ascontiguousarray(model.sample_offsets, dtype=np.int64),
        np.ascontiguousarray(model.sample_points, dtype=np.float64),
        np.ascontiguousarray(model.sample_thickness, dtype=np.float64),
        np.ascontiguousarray(model.sample_area, dtype=np.float64),
        np.ascontiguousarray(model.grid_values, dtype=np.float32),
        np.ascontiguousarray(model.grid_offsets, dtype=np.int64),
        np.ascontiguousarray(model.grid_shape, dtype=np.int64),
        np.ascontiguousarray(model.grid_origin, dtype=np.float64),
        np.ascontiguousarray(model.grid_spacing, dtype=np.float64),
        normals,
        centre,
        reach,
    )


def fibres(model: Model) -> Fibres:
    rest = np.linalg.norm(model.fibre_insertion - model.fibre_origin, axis=1)
    return Fibres(
        np.ascontiguousarray(model.fibre_bones),
        np.ascontiguousarray(model.fibre_origin),
        np.ascontiguousarray(model.fibre_insertion),
        np.ascontiguousarray(model.fibre_ligament),
        rest,
    )


def membrane(model: Model, grd: Grids) -> Membrane:
    s = BONES.index("scaphoid")
    conn = np.ascontiguousarray(model.membrane_connectors)
    radius = BONES.index("radius")
    first_row = (model.membrane_bone[conn[:, 0]] == radius) | (model.membrane_bone[conn[:, 1]] == radius)
    return Membrane(
        conn,
        np.ascontiguousarray(model.membrane_kind),
        first_row & (model.membrane_kind == 0),
        np.ascontiguousarray(model.membrane_bone),
        np.ascontiguousarray(model.membrane_nodes),
        s,
        grd.values,
        int(grd.offsets[s]),
        np.ascontiguousarray(model.grid_shape[s]),
        np.ascontiguousarray(model.grid_origin[s]),
        float(model.grid_spacing[s]),
        np.ascontiguousarray(model.membrane_length),
        grd.normals,
    )


ACROSS_SHARE = 0.25
"""Stiffness of the RSC membrane's across connectors as a share of its along connectors'."""
COURANT = 1.5
"""Largest dt·ω the membrane's free nodes may reach (ω² = their stiffest mode's stiffness over their
mass, `node_mass`). Measured on P1's calibration trial with the population design and the RSC
stiffer, nodes at 2e-7 t: RSC +1.8 SD (dt·ω 1.67) settles in 2,141 steps, +2.1 SD (1.70) in 3,710,
+2.4 SD (1.73) not at all (8 N left after the hold limit); a design with the RSC at +2.9 SD settles
at node masses giving 1.60, not 1.70. So the limit is ≈ 1.70, and 1.5 is ~0.9 of it. The
population design is at 1.46."""


def membrane_eigenvalue(model: Model, mem: Membrane) -> float:
    """The stiffest mode (N/mm) of the RSC membrane's free nodes at rest per N/mm of its along
    connectors (across ones at `ACROSS_SHARE`): the largest eigenvalue of their stiffness matrix,
    stretched connectors' axial stiffness only, the nodes attached to bones held."""
    free = np.asarray(model.membrane_bone) < 0
    index = np.cumsum(free) - 1
    n = int(free.sum())
    K = np.zeros((3 * n, 3 * n))
    for (i, j), kind in zip(mem.connectors, mem.kind):
        d = mem.rest[j] - mem.rest[i]
        block = (1.0 if kind == 0 else ACROSS_SHARE) * np.outer(d, d) / (d @ d)
        for a, b in ((i, j), (j, i)):
            if free[a]:
                ra = slice(3 * index[a], 3 * index[a] + 3)
                K[ra, ra] += block
                if free[b]:
                    K[ra, 3 * index[b] : 3 * index[b] + 3] -= block
    return float(np.linalg.eigvalsh(K)[-1]) if n else 0.0


def membrane_stiffest(st: Settings, eigenvalue: float, m_l0: np.ndarray, m_K: np.ndarray) -> float:
    """Stiffness (N/mm) of the membrane's stiffest free-node mode for one design's connectors (m_l0, m_K of
    `design_arrays`): `membrane_eigenvalue` × the along connectors' stiffness + the node–scaphoid contact's."""
    return eigenvalue * float(np.max(m_K / m_l0)) + st.membrane_contact_stiffness


def node_mass(st: Settings, eigenvalue: float, m_l0: np.ndarray, m_K: np.ndarray) -> float:
    """Mass (t) of the membrane's free nodes for one design's connectors (m_l0, m_K of `design_arrays`):
    st.node_mass, raised to keep dt·ω ≤ `COURANT` where ω² = (eigenvalue × the along connectors'
    stiffness + the node–scaphoid contact stiffness) / mass (`membrane_eigenvalue`). Mass scaling to
    the time step, as explicit finite-element codes do; a quasi-static answer does not depend on it."""
    if st.node_mass <= 0.0 or len(m_K) == 0:
        return float(st.node_mass)
    return max(float(st.node_mass), membrane_stiffest(st, eigenvalue, m_l0, m_K) * (st.dt / COURANT) ** 2)


def design_arrays(
    model: Model, fib: Fibres, mem: Membrane, design: Design
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per-fibre (l0, K) and per-connector (l0, K) of a design; K = 0 for torn ligaments.

    l0 = l_ref / reference_strain per fibre (l_ref its neutral length, whose bundle
    mean is the bundle's reference length); K = (k / n_fibres)·l0, so the bundle's
    fibres share its stiffness k. The RSC's k is the membrane's stiffness along
    its length: its n_across longitudinal chains of (n_along − 1) connectors in
    parallel; across connectors take `ACROSS_SHARE` of the along connectors' stiffness.
    """
    k, r, torn = ligament_arrays(design)
    lig = fib.ligament
    counts = np.bincount(lig, minlength=len(k)).astype(float)
    f_l0 = fib.rest_length / r[lig]
    f_K = np.where(torn[lig], 0.0, k[lig] / np.maximum(counts[lig], 1) * f_l0)
    kind = mem.kind
    n_across = int(np.sum(mem.first_row))
    n_along_segments = int(np.sum(kind == 0)) / max(n_across, 1)
    k_along = k[RSC] * n_along_segments / max(n_across, 1)
    m_l0 = mem.rest_length / r[RSC]
    m_k = np.where(kind == 0, k_along, ACROSS_SHARE * k_along)
    m_K = 0.0 if torn[RSC] else 1.0
    return f_l0, f_K, m_l0, m_K * m_k * m_l0


def settings_tuple(s: SolverSettings, driver: int) -> Settings:
    return Settings(
        float(s.dt_s),
        int(s.settle_steps),
        int(s.move_steps),
        int(s.ramp_steps),
        int(s.min_hold_steps),
        int(s.max_hold_steps),
        float(s.tolerance),
        float(s.force_floor_n),
        float(s.damping_per_s),
        float(s.rot_damping_per_s),
        float(s.fibre_damping_s),
        float(s.active_band_mm),
        float(s.node_mass_t),
        float(s.membrane_contact_stiffness),
        int(driver),
        float(s.max_disp_mm),
        float(np.radians(s.max_rot_deg)),
        float(s.fire_alpha0),
        bool(s.smooth_normals),
        bool(s.block_mass),
        float(s.block_courant),
        float(s.block_floor),
        max(int(s.block_refresh_steps), 1),
        float(s.block_max_move_mm),
        int(s.membrane_substeps),
        float(s.membrane_substep_damping_per_s),
        bool(s.block_refresh_restart),
        bool(s.predict),
        int(s.predict_ramp_steps),
    )
