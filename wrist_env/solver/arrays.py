"""Kernel inputs: the one place where a `Model`, a `Design` and settings become arrays.

The kernels take named tuples of contiguous arrays (Numba handles them as
plain records). Nothing here runs in a hot loop.
"""

from __future__ import annotations

import weakref
from collections import namedtuple

import numpy as np

from wrist_env.design import Design, ligament_arrays
from wrist_env.ligaments import CH_JOINT_STIFFNESS, RSC_INDEX
from wrist_env.model import BONES, PAIR_BONES, PAIRS, Model
from wrist_env.solver.contact import nodal_normals
from wrist_env.solver.settings import SolverSettings

Bodies = namedtuple("Bodies", "com0 inv_mass inv_inertia mass inertia joint_centre joint_axes joint_stiffness")
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


def bodies(model: Model, s: SolverSettings) -> Bodies:
    mass = model.mass * s.mass_scale
    inertia = model.inertia * (s.mass_scale * s.inertia_scale)
    inv_mass = np.where(mass > 0, 1.0 / np.where(mass > 0, mass, 1.0), 0.0)
    inv_inertia = np.array([np.linalg.inv(I) if m > 0 else np.zeros((3, 3)) for I, m in zip(inertia, mass)])
    return Bodies(np.ascontiguousarray(model.com), inv_mass, inv_inertia, mass, inertia, *capitohamate_joint(model))


def capitohamate_joint(model: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The capitohamate joint's in-plane constraint (`forces.joint_forces`): its centre (3,) mm, the
    area-weighted mean of the hamate's contact samples on the capitate at neutral; its axes (3, 3), rows
    in the RCS at neutral (carried by the capitate): dorsopalmar (the RCS volar axis x in the joint's
    plane), proximodistal in the plane, and the normal (the samples' area-weighted mean normal, hamate to
    capitate); and its stiffness (6,) along and about them (`ligaments.CH_JOINT_STIFFNESS`). A model without
    samples on that pair (a synthetic test model) gets zero stiffness."""
    k = PAIRS.index("capitohamate")
    lo, hi = model.sample_offsets[k], model.sample_offsets[k + 1]
    area = np.asarray(model.sample_area[lo:hi], np.float64)
    if hi <= lo or area.sum() <= 0:
        return np.zeros(3), np.eye(3), np.zeros(6)
    centre = area @ np.asarray(model.sample_points[lo:hi], np.float64) / area.sum()
    normal = area @ np.asarray(model.sample_normals[lo:hi], np.float64)
    normal /= np.linalg.norm(normal)
    volar = np.array([1.0, 0.0, 0.0]) - normal[0] * normal
    volar /= np.linalg.norm(volar)
    axes = np.vstack([volar, np.cross(normal, volar), normal])
    return centre, np.ascontiguousarray(axes), np.array(CH_JOINT_STIFFNESS, dtype=np.float64)


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
