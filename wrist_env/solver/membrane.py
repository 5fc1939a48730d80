"""The RSC membrane (Numba): its nodes carried by their bones, its connectors' tensions and the scaphoid's
contact on its free nodes (N, mm), and the free nodes subcycled: several cheap node steps per explicit step.

The membrane's free nodes are the lightest and the softest part of the model. Sliding over the
scaphoid, or with their connectors slack, they have next to no stiffness, so they are the slowest
modes of the model; and their stiffest modes, the connectors along their length, ring at the step's
stability limit (dt·ω up to `arrays.COURANT`). Under the block mass the bones settle in a few tens
of steps, and then wait for the nodes: on P1's calibration trial the scaphoid's net force bounced
between 0.02 and 0.6 N for the last 70 of a frame's 130 steps while the nodes' forces did the same.

So the nodes take `Settings.membrane_substeps` extra steps of their own per explicit step, the bones
held (subcycling, as explicit finite-element codes integrate light parts on a finer clock), with
mass-proportional damping `Settings.membrane_substep_damping` (1/s). A substep recomputes the
connectors' tensions, and the scaphoid's contact on every node that may touch it: each node's distance
is looked up at the substeps' start and again only once it has moved far enough to reach the bone
(`LIPSCHITZ`), so no contact is missed and most substeps need no look-up. The answer is the
equilibrium of `membrane_forces`; only the path to it is faster.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from wrist_env.solver.contact import sdf_distance, sdf_lookup_scalar, sdf_lookup_smooth
from wrist_env.solver.forces import apply_force, rotate, to_local, to_world
from wrist_env.solver.ligaments import blankevoort_energy, blankevoort_force

LIPSCHITZ = np.sqrt(3.0)
"""Bound on the trilinear signed distance's slope (each axis' difference of a distance field is at most
1): a node that has moved t mm since its distance d was looked up is at least d − √3·t from the bone."""


@njit(cache=True, error_model="numpy")
def place_nodes(R, x, com0, mem, nodes):
    """Move the membrane nodes attached to a bone with it."""
    for i in range(nodes.shape[0]):
        b = mem.bone[i]
        if b >= 0:
            nodes[i, 0], nodes[i, 1], nodes[i, 2] = to_world(
                R, x, com0, b, mem.rest[i, 0], mem.rest[i, 1], mem.rest[i, 2]
            )


@njit(cache=True, error_model="numpy", inline="always")
def connector_pull(nodes, i, j, l0, K):
    """A membrane connector from node i to node j of zero-load length l0 (mm) and scale K (N): its
    tension per unit length (N/mm; 0 when slack), the vector from i to j (mm), its length (mm) and strain."""
    dx, dy, dz = nodes[j, 0] - nodes[i, 0], nodes[j, 1] - nodes[i, 1], nodes[j, 2] - nodes[i, 2]
    length = np.sqrt(dx * dx + dy * dy + dz * dz)
    strain = length / l0 - 1.0
    if strain <= 0.0:
        return 0.0, dx, dy, dz, length, strain
    return blankevoort_force(K, strain) / length, dx, dy, dz, length, strain


@njit(cache=True, error_model="numpy", inline="always")
def node_contact(state, com0, mem, contact_stiffness, i, smooth):
    """The scaphoid's push (N, world) on node i of the membrane `mem` (`arrays.Membrane`) at `state`
    (`step.State`; com0 (n_bodies, 3) mm the bodies' neutral centres of mass) under contact_stiffness (N/mm),
    the node's signed distance (mm) and whether it touches (a negative distance with a normal; else no push)."""
    R, x, nodes = state.R, state.x, state.nodes
    s = mem.scaphoid
    qx, qy, qz = to_local(R, x, com0, s, nodes[i, 0], nodes[i, 1], nodes[i, 2])
    if smooth:
        d, gx, gy, gz = sdf_lookup_smooth(
            mem.grid_values,
            mem.grid_normals,
            mem.grid_offset,
            mem.grid_shape,
            mem.grid_origin,
            mem.grid_spacing,
            qx,
            qy,
            qz,
        )
    else:
        d, gx, gy, gz = sdf_lookup_scalar(
            mem.grid_values, mem.grid_offset, mem.grid_shape, mem.grid_origin, mem.grid_spacing, qx, qy, qz
        )
    if d < 0.0:
        gn = np.sqrt(gx * gx + gy * gy + gz * gz)
        if gn > 1e-12:
            scale = contact_stiffness * -d / gn
            fx, fy, fz = rotate(R, s, gx * scale, gy * scale, gz * scale)
            return fx, fy, fz, d, True
    return 0.0, 0.0, 0.0, d, False


@njit(cache=True, error_model="numpy", inline="always")
def connector_forces(mem, nodes, l0, K, force, want_energy):
    """force (M, 3) N += each taut connector's pull on its two nodes; returns (their energy N·mm, 0 unless
    want_energy; the tension N of the radial row of along connectors)."""
    energy = 0.0
    along = 0.0
    for c in range(l0.shape[0]):
        if K[c] == 0.0:
            continue
        i, j = mem.connectors[c, 0], mem.connectors[c, 1]
        tension, dx, dy, dz, length, strain = connector_pull(nodes, i, j, l0[c], K[c])
        if strain <= 0.0:
            continue
        force[i, 0] += tension * dx
        force[i, 1] += tension * dy
        force[i, 2] += tension * dz
        force[j, 0] -= tension * dx
        force[j, 1] -= tension * dy
        force[j, 2] -= tension * dz
        if want_energy:
            energy += blankevoort_energy(K[c], l0[c], strain)
        if mem.first_row[c]:
            along += tension * length
    return energy, along


@njit(cache=True, error_model="numpy")
def membrane_forces(state, com0, mem, contact_stiffness, stiffness, work, want_energy, smooth):
    """RSC membrane (`mem`, `arrays.Membrane`): connector tension (stiffness.m_l0, stiffness.m_K,
    `step.Stiffness`) and node–scaphoid contact (contact_stiffness, N/mm; com0 (n_bodies, 3) mm the bodies'
    neutral centres of mass). The parts of `arrays.System` it reads, not the whole (`forces.contact_forces`).

    state.nodes (n_nodes, 3): world positions (attached nodes already placed on their bones).
    work.node_force (n_nodes, 3) receives forces (N) on the free nodes; forces on attached
    nodes go to their bones (work.F, work.T: `step.Work`). Returns (energy N·mm, tension N of
    the membrane's radial row of along connectors).
    """
    x, nodes = state.x, state.nodes
    l0, K = stiffness.m_l0, stiffness.m_K
    F, T, node_force = work.F, work.T, work.node_force
    node_force[:] = 0.0
    energy, along = connector_forces(mem, nodes, l0, K, node_force, want_energy)
    for i in range(nodes.shape[0]):
        if mem.bone[i] >= 0:
            continue
        fx, fy, fz, d, touching = node_contact(state, com0, mem, contact_stiffness, i, smooth)
        if touching:
            node_force[i, 0] += fx
            node_force[i, 1] += fy
            node_force[i, 2] += fz
            apply_force(F, T, x, mem.scaphoid, (-fx, -fy, -fz), (nodes[i, 0], nodes[i, 1], nodes[i, 2]))
            energy += 0.5 * contact_stiffness * d * d
    for i in range(nodes.shape[0]):
        b = mem.bone[i]
        if b >= 0:
            apply_force(
                F,
                T,
                x,
                b,
                (node_force[i, 0], node_force[i, 1], node_force[i, 2]),
                (nodes[i, 0], nodes[i, 1], nodes[i, 2]),
            )
            node_force[i, 0] = node_force[i, 1] = node_force[i, 2] = 0.0
    return energy, along


@njit(cache=True, error_model="numpy", inline="always")
def _gaps(state, system, gap, travel):
    """gap (n_nodes,) ← each free node of `state` (`step.State`)'s signed distance (mm) to the scaphoid
    of `system` (`arrays.System`) (+inf for an attached node); travel (n_nodes,) ← 0."""
    R, x, nodes = state.R, state.x, state.nodes
    com0, mem = system.bodies.com0, system.membrane
    s = mem.scaphoid
    for i in range(nodes.shape[0]):
        travel[i] = 0.0
        gap[i] = np.inf
        if mem.bone[i] < 0:
            qx, qy, qz = to_local(R, x, com0, s, nodes[i, 0], nodes[i, 1], nodes[i, 2])
            gap[i] = sdf_distance(
                mem.grid_values, mem.grid_offset, mem.grid_shape, mem.grid_origin, mem.grid_spacing, qx, qy, qz
            )


@njit(cache=True, error_model="numpy", inline="always")
def _substep_forces(state, system, stiffness, gap, travel, force, smooth):
    """force (n_nodes, 3) N ← connector tensions (stiffness.m_l0, stiffness.m_K) and the scaphoid's contact
    on the nodes of `state`, looked up only on the free nodes that may touch it (gap − √3·travel < 0:
    `LIPSCHITZ`), whose gap and travel (n_nodes,) then restart there."""
    nodes, com0, mem = state.nodes, system.bodies.com0, system.membrane
    k = system.settings.membrane_contact_stiffness
    force[:] = 0.0
    connector_forces(mem, nodes, stiffness.m_l0, stiffness.m_K, force, np.bool_(False))
    for i in range(nodes.shape[0]):
        if not gap[i] - LIPSCHITZ * travel[i] < 0.0:
            continue
        fx, fy, fz, gap[i], _ = node_contact(state, com0, mem, k, i, smooth)
        travel[i] = 0.0
        force[i, 0] += fx
        force[i, 1] += fy
        force[i, 2] += fz


@njit(cache=True, error_model="numpy")
def substep(state, system, stiffness, scratch, smooth):
    """Move the free nodes state.nodes (n_nodes, 3) mm, velocities state.nv (n_nodes, 3) mm/s (`step.State`),
    through st.membrane_substeps steps of st.dt (st: system.settings) with the bones held, under the
    connectors and node mass (t) of `stiffness` (`step.Stiffness`); scratch: (2, n_nodes, 3) arrays
    (`new_scratch`)."""
    nodes, nv = state.nodes, state.nv
    mem, st = system.membrane, system.settings
    node_mass = stiffness.node_mass
    force = scratch[0]
    gap, travel = scratch[1, :, 0], scratch[1, :, 1]
    _gaps(state, system, gap, travel)
    dt = st.dt
    lin = 1.0 / (1.0 + st.membrane_substep_damping * dt)
    for _ in range(st.membrane_substeps):
        _substep_forces(state, system, stiffness, gap, travel, force, smooth)
        for i in range(nodes.shape[0]):
            if mem.bone[i] < 0:
                step2 = 0.0
                for k in range(3):
                    nv[i, k] = (nv[i, k] + dt / node_mass * force[i, k]) * lin
                    nodes[i, k] += dt * nv[i, k]
                    step2 += (dt * nv[i, k]) ** 2
                travel[i] += np.sqrt(step2)


@njit(cache=True)
def new_scratch(nodes):
    """Scratch for `substep`: (2, n_nodes, 3)."""
    return np.zeros((2,) + nodes.shape)
