"""The RSC membrane's free nodes, subcycled: several cheap node steps per explicit step (Numba).

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
equilibrium of `forces.membrane_forces`; only the path to it is faster.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from wrist_env.solver.contact import sdf_distance
from wrist_env.solver.forces import connector_pull, node_contact, to_local

LIPSCHITZ = np.sqrt(3.0)
"""Bound on the trilinear signed distance's slope (each axis' difference of a distance field is at most
1): a node that has moved t mm since its distance d was looked up is at least d − √3·t from the bone."""


@njit(cache=True, error_model="numpy")
def _gaps(R, x, com0, mem, nodes, gap, travel):
    """gap (M,) ← each free node's signed distance (mm) to the scaphoid (+inf for an attached node);
    travel (M,) ← 0."""
    s = mem.scaphoid
    for i in range(nodes.shape[0]):
        travel[i] = 0.0
        gap[i] = np.inf
        if mem.bone[i] < 0:
            qx, qy, qz = to_local(R, x, com0, s, nodes[i, 0], nodes[i, 1], nodes[i, 2])
            gap[i] = sdf_distance(
                mem.grid_values, mem.grid_offset, mem.grid_shape, mem.grid_origin, mem.grid_spacing, qx, qy, qz
            )


@njit(cache=True, error_model="numpy")
def _substep_forces(R, x, com0, mem, nodes, l0, K, contact_stiffness, gap, travel, force, smooth):
    """force (M, 3) N ← connector tensions and the scaphoid's contact, looked up only on the free nodes that
    may touch it (gap − √3·travel < 0: `LIPSCHITZ`), whose gap and travel then restart there."""
    force[:] = 0.0
    for c in range(l0.shape[0]):
        if K[c] == 0.0:
            continue
        i, j = mem.connectors[c, 0], mem.connectors[c, 1]
        tension, dx, dy, dz, _, strain = connector_pull(nodes, i, j, l0[c], K[c])
        if strain <= 0.0:
            continue
        force[i, 0] += tension * dx
        force[i, 1] += tension * dy
        force[i, 2] += tension * dz
        force[j, 0] -= tension * dx
        force[j, 1] -= tension * dy
        force[j, 2] -= tension * dz
    for i in range(nodes.shape[0]):
        if not gap[i] - LIPSCHITZ * travel[i] < 0.0:
            continue
        fx, fy, fz, gap[i], _ = node_contact(
            R, x, com0, mem, nodes[i, 0], nodes[i, 1], nodes[i, 2], contact_stiffness, smooth
        )
        travel[i] = 0.0
        force[i, 0] += fx
        force[i, 1] += fy
        force[i, 2] += fz


@njit(cache=True, error_model="numpy")
def substep(R, x, com0, mem, nodes, nv, l0, K, node_mass, st, scratch):
    """Move the free nodes (M, 3) mm, velocities nv (M, 3) mm/s, through st.membrane_substeps steps of
    st.dt with the bones held; scratch: (2, M, 3) arrays (`new_scratch`)."""
    force = scratch[0]
    gap, travel = scratch[1, :, 0], scratch[1, :, 1]
    _gaps(R, x, com0, mem, nodes, gap, travel)
    dt = st.dt
    lin = 1.0 / (1.0 + st.membrane_substep_damping * dt)
    for _ in range(st.membrane_substeps):
        _substep_forces(
            R, x, com0, mem, nodes, l0, K, st.membrane_contact_stiffness, gap, travel, force, st.smooth_normals
        )
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
    """Scratch for `substep`: (2, M, 3)."""
    return np.zeros((2,) + nodes.shape)
