"""Force kernels of one explicit step: contact, fibres, RSC membrane (Numba).

Bodies are indexed as in `wrist_env.model.BONES`. A body's state is its
rotation R (3, 3), the world position x (3,) of its centre of mass, linear
velocity v and angular velocity w (world). A neutral-pose point p of the
body is at R (p − com0) + x. Forces F (N) and torques T (N·mm, about the
centre of mass) are accumulated into arrays of shape (n_bodies, 3).

The kernels work on scalars (3-vectors as tuples) so the hot loops allocate
nothing.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from wrist_env.model import CAPITATE, HAMATE
from wrist_env.solver.contact import law_energy, law_pressure, sdf_distance, sdf_lookup_scalar, sdf_lookup_smooth
from wrist_env.solver.ligaments import blankevoort_energy, blankevoort_force
from wrist_env.solver.rigid import rotvec_between

# columns of the per-pair contact statistics the force kernels accumulate
C_FORCE, C_AREA, C_PEAK = 0, 1, 2
CONTACT_FIELDS = ("mean_pressure_mpa", "peak_pressure_mpa", "area_mm2", "force_n")
"""Columns of `Result.contact` (per frame and pair): mean pressure over the contacting area (MPa),
peak pressure (MPa), contact area (mm²), force (N)."""
R_MEAN, R_PEAK, R_AREA, R_FORCE = (CONTACT_FIELDS.index(f) for f in CONTACT_FIELDS)


@njit(cache=True, error_model="numpy", inline="always")
def to_world(R, x, com0, b, px, py, pz):
    """World position of neutral-pose point p of body b."""
    qx, qy, qz = px - com0[b, 0], py - com0[b, 1], pz - com0[b, 2]
    return (
        R[b, 0, 0] * qx + R[b, 0, 1] * qy + R[b, 0, 2] * qz + x[b, 0],
        R[b, 1, 0] * qx + R[b, 1, 1] * qy + R[b, 1, 2] * qz + x[b, 1],
        R[b, 2, 0] * qx + R[b, 2, 1] * qy + R[b, 2, 2] * qz + x[b, 2],
    )


@njit(cache=True, error_model="numpy", inline="always")
def to_local(R, x, com0, b, wx, wy, wz):
    """Neutral-pose coordinates in body b of world point w."""
    qx, qy, qz = wx - x[b, 0], wy - x[b, 1], wz - x[b, 2]
    return (
        R[b, 0, 0] * qx + R[b, 1, 0] * qy + R[b, 2, 0] * qz + com0[b, 0],
        R[b, 0, 1] * qx + R[b, 1, 1] * qy + R[b, 2, 1] * qz + com0[b, 1],
        R[b, 0, 2] * qx + R[b, 1, 2] * qy + R[b, 2, 2] * qz + com0[b, 2],
    )


@njit(cache=True, error_model="numpy", inline="always")
def rotate(R, b, gx, gy, gz):
    return (
        R[b, 0, 0] * gx + R[b, 0, 1] * gy + R[b, 0, 2] * gz,
        R[b, 1, 0] * gx + R[b, 1, 1] * gy + R[b, 1, 2] * gz,
        R[b, 2, 0] * gx + R[b, 2, 1] * gy + R[b, 2, 2] * gz,
    )


@njit(cache=True, error_model="numpy", inline="always")
def apply_force(F, T, x, b, f, p):
    """Add force f (N, world) applied at world point p (mm), each a 3-tuple, to body b."""
    fx, fy, fz = f
    px, py, pz = p
    rx, ry, rz = px - x[b, 0], py - x[b, 1], pz - x[b, 2]
    F[b, 0] += fx
    F[b, 1] += fy
    F[b, 2] += fz
    T[b, 0] += ry * fz - rz * fy
    T[b, 1] += rz * fx - rx * fz
    T[b, 2] += rx * fy - ry * fx


@njit(cache=True, error_model="numpy", inline="always")
def pair_transform(R, x, com0, a, b):
    """(M, t) as 12 scalars: neutral-pose point p of body a lies at M p + t in body b's neutral frame."""
    m00 = R[b, 0, 0] * R[a, 0, 0] + R[b, 1, 0] * R[a, 1, 0] + R[b, 2, 0] * R[a, 2, 0]
    m01 = R[b, 0, 0] * R[a, 0, 1] + R[b, 1, 0] * R[a, 1, 1] + R[b, 2, 0] * R[a, 2, 1]
    m02 = R[b, 0, 0] * R[a, 0, 2] + R[b, 1, 0] * R[a, 1, 2] + R[b, 2, 0] * R[a, 2, 2]
    m10 = R[b, 0, 1] * R[a, 0, 0] + R[b, 1, 1] * R[a, 1, 0] + R[b, 2, 1] * R[a, 2, 0]
    m11 = R[b, 0, 1] * R[a, 0, 1] + R[b, 1, 1] * R[a, 1, 1] + R[b, 2, 1] * R[a, 2, 1]
    m12 = R[b, 0, 1] * R[a, 0, 2] + R[b, 1, 1] * R[a, 1, 2] + R[b, 2, 1] * R[a, 2, 2]
    m20 = R[b, 0, 2] * R[a, 0, 0] + R[b, 1, 2] * R[a, 1, 0] + R[b, 2, 2] * R[a, 2, 0]
    m21 = R[b, 0, 2] * R[a, 0, 1] + R[b, 1, 2] * R[a, 1, 1] + R[b, 2, 2] * R[a, 2, 1]
    m22 = R[b, 0, 2] * R[a, 0, 2] + R[b, 1, 2] * R[a, 1, 2] + R[b, 2, 2] * R[a, 2, 2]
    # t = com0_b + R_bᵀ (x_a − x_b) − M com0_a
    tx, ty, tz = to_local(R, x, com0, b, x[a, 0], x[a, 1], x[a, 2])
    cx, cy, cz = com0[a, 0], com0[a, 1], com0[a, 2]
    tx -= m00 * cx + m01 * cy + m02 * cz
    ty -= m10 * cx + m11 * cy + m12 * cz
    tz -= m20 * cx + m21 * cy + m22 * cz
    return m00, m01, m02, m10, m11, m12, m20, m21, m22, tx, ty, tz


@njit(cache=True, error_model="numpy", inline="always")
def _moved(grids, M, s):
    """Sample s's position under the pair transform M (12 scalars), in the grid bone's neutral frame."""
    m00, m01, m02, m10, m11, m12, m20, m21, m22, tx, ty, tz = M
    p = grids.points
    px, py, pz = p[s, 0], p[s, 1], p[s, 2]
    return (
        m00 * px + m01 * py + m02 * pz + tx,
        m10 * px + m11 * py + m12 * pz + ty,
        m20 * px + m21 * py + m22 * pz + tz,
    )


@njit(cache=True, error_model="numpy", inline="always")
def sample_lookup(grids, b, M, s):
    """Signed distance (mm), gradient and position (b's neutral frame) of sample s under the pair transform M."""
    qx, qy, qz = _moved(grids, M, s)
    d, gx, gy, gz = sdf_lookup_scalar(
        grids.values, grids.offsets[b], grids.shape[b], grids.origin[b], grids.spacing[b], qx, qy, qz
    )
    return d, gx, gy, gz, qx, qy, qz


@njit(cache=True, error_model="numpy", inline="always")
def sample_lookup_smooth(grids, b, M, s):
    """As `sample_lookup`, with the direction interpolated from the grid's nodal normals where d < 0."""
    qx, qy, qz = _moved(grids, M, s)
    d, gx, gy, gz = sdf_lookup_smooth(
        grids.values, grids.normals, grids.offsets[b], grids.shape[b], grids.origin[b], grids.spacing[b], qx, qy, qz
    )
    return d, gx, gy, gz, qx, qy, qz


@njit(cache=True, error_model="numpy", inline="always")
def sample_distance(grids, b, M, s):
    """Signed distance (mm) of sample s under the pair transform M (no gradient)."""
    qx, qy, qz = _moved(grids, M, s)
    return sdf_distance(grids.values, grids.offsets[b], grids.shape[b], grids.origin[b], grids.spacing[b], qx, qy, qz)


@njit(cache=True, error_model="numpy", inline="always")
def _travel(grids, p, M, ref):
    """Upper bound (mm) on how far any sample of pair p has moved in the grid bone's frame since its
    pair transform was ref[p] (12 values, `pair_transform`'s order): |ΔM|·reach + |ΔM c + Δt|
    about the pair's sample centre c; NaN if ref[p] is unset."""
    c = grids.pair_centre[p]
    norm2 = 0.0
    for k in range(9):
        dm = M[k] - ref[p, k]
        norm2 += dm * dm
    shift2 = 0.0
    for r in range(3):
        dm0, dm1, dm2 = M[3 * r] - ref[p, 3 * r], M[3 * r + 1] - ref[p, 3 * r + 1], M[3 * r + 2] - ref[p, 3 * r + 2]
        dr = dm0 * c[0] + dm1 * c[1] + dm2 * c[2] + M[9 + r] - ref[p, 9 + r]
        shift2 += dr * dr
    return np.sqrt(norm2) * grids.pair_reach[p] + np.sqrt(shift2)


@njit(cache=True, error_model="numpy")
def _refill(grids, p, b, M, band_mm, active, n_active, ref):
    """Refill pair p's active samples (those within `band_mm` of contact) and remember M as ref[p]."""
    n = 0
    start = grids.sample_offsets[p]
    for s in range(start, grids.sample_offsets[p + 1]):
        if sample_distance(grids, b, M, s) < band_mm:
            active[start + n] = s
            n += 1
    n_active[p] = n
    for k in range(12):
        ref[p, k] = M[k]


@njit(cache=True, error_model="numpy")
def rebuild_active(R, x, com0, grids, band_mm, active, n_active, ref):
    """Refill every pair's active samples (`_refill`) at the state (R, x)."""
    for p in range(grids.pair_bones.shape[0]):
        a, b = grids.pair_bones[p, 0], grids.pair_bones[p, 1]
        _refill(grids, p, b, pair_transform(R, x, com0, a, b), band_mm, active, n_active, ref)


@njit(cache=True, error_model="numpy")
def sample_pressures(R, x, com0, grids, law, pressure):
    """Contact pressure (MPa) of every sample (pressure, shape (n_samples,)) at the state (R, x)."""
    for p in range(grids.pair_bones.shape[0]):
        a, b = grids.pair_bones[p, 0], grids.pair_bones[p, 1]
        M = pair_transform(R, x, com0, a, b)
        for s in range(grids.sample_offsets[p], grids.sample_offsets[p + 1]):
            d = sample_distance(grids, b, M, s)
            pressure[s] = law_pressure(law, -d / grids.thickness[s]) if d < 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def contact_forces(state, com0, grids, law, work, band_mm, want_energy, smooth):
    """Contact forces of all pairs' active samples at `state` (`step.State`) of the bodies whose neutral centres
    of mass are com0 (n_bodies, 3) mm, on the pairs' `arrays.Grids` under their `arrays.Law`, into work.F (N)
    and work.T (N·mm) (`step.Work`); returns contact energy (N·mm; 0 unless `want_energy`). It takes the
    parts of `arrays.System` it reads, not the whole: a call passes each array's fields, and the whole
    System's cost a measurable share of a step in a kernel called every step.

    A pair's active samples (work.active, work.n_active: those within `band_mm` of contact) are
    refilled when its samples may have moved band_mm / 2 since the last refill (`_travel`; work.ref:
    (n_pairs, 12) pair transforms at the refills, NaN to force one): the
    trilinear distance changes at most √3× as fast as a sample moves, so no
    sample left out can have reached contact. Each pair's forces and moments
    are summed in the grid bone's neutral frame and applied to both bodies
    once. work.stats (n_pairs, 3) receives per pair: force (N), contacting area
    (mm²), peak pressure (MPa).
    """
    R, x = state.R, state.x
    active, n_active, ref, F, T, stats = work.active, work.n_active, work.ref, work.F, work.T, work.stats
    energy = 0.0
    stats[:] = 0.0
    for p in range(grids.pair_bones.shape[0]):
        a, b = grids.pair_bones[p, 0], grids.pair_bones[p, 1]
        M = pair_transform(R, x, com0, a, b)
        if not _travel(grids, p, M, ref) < 0.5 * band_mm:
            _refill(grids, p, b, M, band_mm, active, n_active, ref)
        start = grids.sample_offsets[p]
        fx = fy = fz = mx = my = mz = 0.0
        force = area_sum = peak = 0.0
        for j in range(n_active[p]):
            s = active[start + j]
            if smooth:
                d, gx, gy, gz, qx, qy, qz = sample_lookup_smooth(grids, b, M, s)
            else:
                d, gx, gy, gz, qx, qy, qz = sample_lookup(grids, b, M, s)
            if d >= 0.0:
                continue
            gn = np.sqrt(gx * gx + gy * gy + gz * gz)
            if gn < 1e-12:
                continue
            h = grids.thickness[s]
            strain = -d / h
            pressure = law_pressure(law, strain)
            area = grids.area[s]
            scale = pressure * area / gn
            sx, sy, sz = gx * scale, gy * scale, gz * scale
            fx += sx
            fy += sy
            fz += sz
            mx += qy * sz - qz * sy
            my += qz * sx - qx * sz
            mz += qx * sy - qy * sx
            if want_energy:
                energy += area * h * law_energy(law, strain)
            force += pressure * area
            area_sum += area
            if pressure > peak:
                peak = pressure
        stats[p, C_FORCE] = force
        stats[p, C_AREA] = area_sum
        stats[p, C_PEAK] = peak
        if area_sum == 0.0:
            continue
        # moment about b's centre of mass, then both to world
        cx, cy, cz = com0[b, 0], com0[b, 1], com0[b, 2]
        mx -= cy * fz - cz * fy
        my -= cz * fx - cx * fz
        mz -= cx * fy - cy * fx
        Fx, Fy, Fz = rotate(R, b, fx, fy, fz)
        Mx, My, Mz = rotate(R, b, mx, my, mz)
        rx, ry, rz = x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2]
        F[a, 0] += Fx
        F[a, 1] += Fy
        F[a, 2] += Fz
        T[a, 0] += Mx + ry * Fz - rz * Fy
        T[a, 1] += My + rz * Fx - rx * Fz
        T[a, 2] += Mz + rx * Fy - ry * Fx
        F[b, 0] -= Fx
        F[b, 1] -= Fy
        F[b, 2] -= Fz
        T[b, 0] -= Mx
        T[b, 1] -= My
        T[b, 2] -= Mz
    return energy


@njit(cache=True, error_model="numpy")
def fibre_forces(state, com0, fibres, damping_s, stiffness, work, want_energy):
    """Blankevoort fibre forces at `state` (`step.State`) of the bodies whose neutral centres of mass are com0
    (n_bodies, 3) mm, on the `arrays.Fibres` damped by damping_s (s), into work.F (N) and work.T (N·mm)
    (`step.Work`); returns strain energy (N·mm; 0 unless `want_energy`).

    stiffness.f_l0, stiffness.f_K (`step.Stiffness`): per-fibre zero-load length (mm) and scale (N per
    unit strain), K = 0 if torn. work.bundle (n_bundles,) receives the summed tension of each bundle (N).
    """
    R, x, v, w = state.R, state.x, state.v, state.w
    l0, K = stiffness.f_l0, stiffness.f_K
    F, T, bundle_force = work.F, work.T, work.bundle
    energy = 0.0
    o, ins = fibres.origin, fibres.insertion
    for i in range(l0.shape[0]):
        if K[i] == 0.0:
            continue
        a, b = fibres.bones[i, 0], fibres.bones[i, 1]
        ax, ay, az = to_world(R, x, com0, a, o[i, 0], o[i, 1], o[i, 2])
        bx, by, bz = to_world(R, x, com0, b, ins[i, 0], ins[i, 1], ins[i, 2])
        dx, dy, dz = bx - ax, by - ay, bz - az
        length = np.sqrt(dx * dx + dy * dy + dz * dz)
        strain = length / l0[i] - 1.0
        if strain <= 0.0:
            continue
        ux, uy, uz = dx / length, dy / length, dz / length
        tension = blankevoort_force(K[i], strain)
        # relative velocity of the ends along the fibre
        ra = (ax - x[a, 0], ay - x[a, 1], az - x[a, 2])
        rb = (bx - x[b, 0], by - x[b, 1], bz - x[b, 2])
        vax = v[a, 0] + w[a, 1] * ra[2] - w[a, 2] * ra[1]
        vay = v[a, 1] + w[a, 2] * ra[0] - w[a, 0] * ra[2]
        vaz = v[a, 2] + w[a, 0] * ra[1] - w[a, 1] * ra[0]
        vbx = v[b, 0] + w[b, 1] * rb[2] - w[b, 2] * rb[1]
        vby = v[b, 1] + w[b, 2] * rb[0] - w[b, 0] * rb[2]
        vbz = v[b, 2] + w[b, 0] * rb[1] - w[b, 1] * rb[0]
        rate = (vbx - vax) * ux + (vby - vay) * uy + (vbz - vaz) * uz
        if rate > 0.0:
            tension += damping_s * (K[i] / l0[i]) * rate
        apply_force(F, T, x, a, (tension * ux, tension * uy, tension * uz), (ax, ay, az))
        apply_force(F, T, x, b, (-tension * ux, -tension * uy, -tension * uz), (bx, by, bz))
        bundle_force[fibres.ligament[i]] += tension
        if want_energy:
            energy += blankevoort_energy(K[i], l0[i], strain)
    return energy


@njit(cache=True, error_model="numpy")
def joint_forces(state, bod, work, want_energy):
    """The capitohamate joint's in-plane constraint (`arrays.capitohamate_joint`, `ligaments.CH_JOINT_STIFFNESS`):
    a linear spring between the hamate and the capitate at the joint's centre, in the joint's axes carried by
    the capitate. The centre's shift on the hamate from the capitate's, d, gives the hamate −Σ kₖ(eₖ·d)eₖ
    at its centre point (the capitate the opposite at its own), the hamate's turn from the capitate θ
    (`rigid.rotvec_between`) the couple −Σ k₃₊ₖ(eₖ·θ)eₖ (the capitate the opposite), at `state`
    (`step.State`) of the `arrays.Bodies` bod, into work.F (N) and work.T (N·mm) (`step.Work`); returns
    the energy (N·mm; 0 unless `want_energy`)."""
    R, x, com0 = state.R, state.x, bod.com0
    F, T = work.F, work.T
    k = bod.joint_stiffness
    if k[0] == 0.0 and k[1] == 0.0 and k[2] == 0.0 and k[3] == 0.0 and k[4] == 0.0 and k[5] == 0.0:
        return 0.0
    c, E = bod.joint_centre, bod.joint_axes
    hx, hy, hz = to_world(R, x, com0, HAMATE, c[0], c[1], c[2])
    cx, cy, cz = to_world(R, x, com0, CAPITATE, c[0], c[1], c[2])
    d = (hx - cx, hy - cy, hz - cz)
    theta = rotvec_between(R[HAMATE], R[CAPITATE])
    fx = fy = fz = 0.0
    mx = my = mz = 0.0
    energy = 0.0
    for a in range(3):
        ex, ey, ez = rotate(R, CAPITATE, E[a, 0], E[a, 1], E[a, 2])
        s = ex * d[0] + ey * d[1] + ez * d[2]
        r = ex * theta[0] + ey * theta[1] + ez * theta[2]
        fx -= k[a] * s * ex
        fy -= k[a] * s * ey
        fz -= k[a] * s * ez
        mx -= k[3 + a] * r * ex
        my -= k[3 + a] * r * ey
        mz -= k[3 + a] * r * ez
        if want_energy:
            energy += 0.5 * (k[a] * s * s + k[3 + a] * r * r)
    apply_force(F, T, x, HAMATE, (fx, fy, fz), (hx, hy, hz))
    apply_force(F, T, x, CAPITATE, (-fx, -fy, -fz), (cx, cy, cz))
    T[HAMATE, 0] += mx
    T[HAMATE, 1] += my
    T[HAMATE, 2] += mz
    T[CAPITATE, 0] -= mx
    T[CAPITATE, 1] -= my
    T[CAPITATE, 2] -= mz
    return energy
