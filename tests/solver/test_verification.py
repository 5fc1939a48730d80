"""Solver verification against references we did not write into the solver.

1. Ligament fibres holding a free mass: the time history of the explicit
   solver against SciPy's `solve_ivp` (DOP853, rtol 1e-10) of the same
   one-dimensional equation of motion, with the Blankevoort law written out
   here from DESIGN.md.
2. Cartilage contact: a flat square and a spherical cap pressed onto a rigid
   half-space by the idealized driver's compressive load, against the
   closed-form elastic-foundation answer of the tri-linear law.
3. Frame invariance: the whole built participant P1 moved by a rigid
   transform (a 90° turn about a coordinate axis plus a translation) gives the
   same relative kinematics, contact and ligament outputs.

Units: mm, N, MPa, t, s.
"""

from dataclasses import fields, replace

import numpy as np
import pytest
import synthetic as syn
from scipy.integrate import quad, solve_ivp
from scipy.interpolate import RegularGridInterpolator
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from wrist_env import design
from wrist_env.builder.contact_law import fit_contact_law
from wrist_env.ligaments import LIGAMENT_NAMES
from wrist_env.model import BONES, CAPITATE, LUNATE, PAIRS, RADIUS, SCAPHOID
from wrist_env.participants.builtin import truth
from wrist_env.solver.drivers import experimental, idealized
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import simulate

LUNOCAPITATE = PAIRS.index("lunocapitate")
MEAN, PEAK, AREA, FORCE = range(4)
EPSILON_L = 0.03  # Blankevoort's spring parameter (DESIGN.md)
_FIELDS = {f.name for f in fields(SolverSettings)}


# --------------------------------------------------------------------------- helpers


def blankevoort(K, strain):
    """Tension (N) of a fibre of scale K = k·l0 (N per unit strain), Blankevoort 1991 as in DESIGN.md."""
    if strain <= 0.0:
        return 0.0
    if strain <= 2.0 * EPSILON_L:
        return K * strain * strain / (4.0 * EPSILON_L)
    return K * (strain - EPSILON_L)


def trilinear(law, e):
    """Pressure (MPa) of the tri-linear law [e1, e2, k1, k2, k3] at strain e (0 for e <= 0)."""
    e1, e2, k1, k2, k3 = law
    if e <= 0.0:
        return 0.0
    if e <= e1:
        return k1 * e
    if e <= e2:
        return k1 * e1 + k2 * (e - e1)
    return k1 * e1 + k2 * (e2 - e1) + k3 * (e - e2)


def sampled_every(settings: SolverSettings, n: int) -> SolverSettings:
    """Settings with no settling or moving stage to speak of and the state sampled every n steps.

    With the adaptive schedule (ramp, then hold until equilibrium between
    `min_hold_steps` and `max_hold_steps`) every stage is held for exactly n
    steps; a stage runs at least one step, so settling takes one and the move
    n, which `Result.steps` (steps since the previous frame, frame 0 counting
    settling and the move) accounts for. The older fixed schedule
    (`frame_steps`, the first frame taking frame_steps // 2) is handled too.
    """
    if "frame_steps" in _FIELDS:
        return replace(settings, settle_steps=0, move_steps=0, frame_steps=n)
    return replace(settings, settle_steps=0, move_steps=0, ramp_steps=0, min_hold_steps=n, max_hold_steps=n)


def sample_times(result, settings: SolverSettings, n: int) -> np.ndarray:
    """Time (s) since the start at the end of each frame of a run with `sampled_every(settings, n)`."""
    n_frames = len(result.poses)
    if hasattr(result, "steps"):
        assert np.all(result.steps[1:] == n), result.steps[:5]
        return settings.dt_s * np.cumsum(result.steps)
    return settings.dt_s * (n // 2 + n * np.arange(n_frames))


def undamped(settings: SolverSettings) -> SolverSettings:
    """No damping of any kind and no FIRE: the bare explicit integrator."""
    return replace(settings, damping_per_s=0.0, rot_damping_per_s=0.0, fibre_damping_s=0.0, fire_alpha0=0.0)


def upward_crossings(t, y, level):
    """Times (linear interpolation) at which y rises through `level`."""
    i = np.flatnonzero((y[:-1] < level) & (y[1:] >= level))
    return t[i] + (t[i + 1] - t[i]) * (level - y[i]) / (y[i + 1] - y[i])


def extremum(y, i):
    """Vertex value of the parabola through samples i − 1, i, i + 1 (uniform sampling)."""
    a, b, c = y[i - 1], y[i], y[i + 1]
    den = a - 2.0 * b + c
    return b if den == 0.0 else b - 0.125 * (c - a) ** 2 / den


def oscillation(t, y, level):
    """(period, largest, smallest) of a sampled oscillation: period from upward crossings of `level`."""
    up = upward_crossings(t, y, level)
    assert len(up) >= 2, "record shorter than one period"
    inner = slice(1, len(y) - 1)
    hi = 1 + int(np.argmax(y[inner]))
    lo = 1 + int(np.argmin(y[inner]))
    return float(np.mean(np.diff(up))), extremum(y, hi), extremum(y, lo)


# --------------------------------------------------------------------------- 1. fibre oscillator

SLIL_V, SLIL_D = LIGAMENT_NAMES.index("SLIL_v"), LIGAMENT_NAMES.index("SLIL_d")
AXIS = np.array([1.0, 2.0, 2.0]) / 3.0  # fibre line, oblique to every coordinate axis
CENTRE = np.array([3.0, -1.0, 2.0])  # scaphoid centre of mass (mm)
MASS_T = 2e-6  # scaphoid mass before mass scaling (t): 2 g

OSCILLATORS = {
    # name: (fibres as (ligament, signed position a of the origin on the line y ↦ CENTRE + y·AXIS)),
    #       {ligament: (stiffness k N/mm, reference strain r)}
    # one fibre: released at strain 0.25, it pulls the body through the toe region, goes slack,
    # the body coasts through the origin point and stretches it from the other side (amplitude = l_ref);
    # opposed fibres stay taut: an asymmetric oscillation about the equilibrium; the bundle of two
    # checks that its stiffness k is shared (K = k/2·l0 per fibre).
    "one fibre": ([(SLIL_D, -10.0)], {SLIL_D: (79.0, 1.25)}),
    "two bundles opposed": ([(SLIL_D, -8.0), (SLIL_V, 12.0)], {SLIL_D: (79.0, 1.05), SLIL_V: (33.0, 1.15)}),
    "one bundle of two fibres opposed": ([(SLIL_D, -8.0), (SLIL_D, 12.0)], {SLIL_D: (79.0, 1.10)}),
}


def oscillator(fibres):
    """A free scaphoid on fibres from the fixed radius, all inserting at its centre of mass (no torque)."""
    com = np.array([[0, 0, 0], [40, 0, 0], CENTRE, [-40, 0, 0], [0, 40, 0]], float)
    mass = np.array([0.0, 0.0, MASS_T, 2e-6, 4e-6])
    inertia = np.array([syn.box_inertia(2e-6, (8, 8, 8))] * 5)
    return syn.model(
        mass=mass,
        com=com,
        inertia=inertia,
        law=[0.1, 0.2, 10, 20, 30],
        fibres=[syn.Fibre(lig, RADIUS, SCAPHOID, CENTRE + a * AXIS, CENTRE) for lig, a in fibres],
    )


@pytest.mark.parametrize("mass_scale", [1.0, 10.0])
@pytest.mark.parametrize("case", list(OSCILLATORS))
def test_fibres_oscillate_as_solve_ivp_predicts(case, mass_scale):
    """Undamped fibres (no FIRE, no damping) holding the free scaphoid at its centre of mass
    oscillate along their common line as SciPy's solve_ivp (DOP853, rtol 1e-10) of
    m·y'' = −Σ T_i(l_i)·∂l_i/∂y predicts, with m = mass × mass_scale, the Blankevoort
    tension T = K ε²/(4ε_l) (ε ≤ 2ε_l), K(ε − ε_l) above, 0 when slack, ε_l = 0.03,
    K = (k / fibres in the bundle)·l0, l0 = l_ref / reference strain. The fibres start
    stretched (reference strain > 1), the body at rest. Asserted: period (from crossings
    of the mid-level) and amplitude within 1 %, the whole sampled trajectory within 1 %
    of the amplitude, and no motion off the line (< 1e-6 mm)."""
    fib, materials = OSCILLATORS[case]
    model = oscillator(fib)
    vector = design.population().vector.copy()
    for lig, (k, r) in materials.items():
        vector[lig], vector[len(LIGAMENT_NAMES) + lig] = k, r
    dsg = design.Design.from_vector(vector)

    # the reference, from the design table and DESIGN.md only
    m = MASS_T * mass_scale
    count = {lig: sum(1 for g, _ in fib if g == lig) for lig in materials}
    a = np.array([p for _, p in fib])
    l0 = np.array([abs(p) / materials[g][1] for g, p in fib])
    K = np.array([materials[g][0] / count[g] * l for (g, _), l in zip(fib, l0)])

    def rhs(t, state):
        y, v = state
        force = sum(-blankevoort(Ki, abs(y - ai) / l0i - 1.0) * np.sign(y - ai) for ai, l0i, Ki in zip(a, l0, K))
        return [v, force / m]

    # time scale: the stiffest linear stretch and the slack coasting, ~1500 steps per period
    omega = np.sqrt(np.sum(K / l0) / m)
    energy = sum(
        Ki * l0i * (2 * EPSILON_L**2 / 3 + 0.5 * (r - 1) ** 2 - EPSILON_L * (r - 1))
        for Ki, l0i, r in zip(K, l0, [materials[g][1] for g, _ in fib])
    )
    coast = 2 * l0.min() / np.sqrt(2 * energy / m) if len(fib) == 1 else 0.0
    period_guess = 2 * np.pi / omega + 2 * coast
    dt = period_guess / 1500
    settings = sampled_every(
        replace(
            undamped(SolverSettings().diagonal()), dt_s=dt, mass_scale=mass_scale, inertia_scale=1.0, max_disp_mm=1e3
        ),
        4,
    )
    n_frames = int(3.2 * period_guess / (4 * dt))
    result = simulate(model, dsg, experimental(model, np.tile(np.eye(4), (n_frames, 1, 1))), settings)
    assert result.ok, result.message
    t = sample_times(result, settings, 4)
    p = result.poses[:, SCAPHOID, :3, 3] + result.poses[:, SCAPHOID, :3, :3] @ CENTRE - CENTRE  # com displacement
    y = p @ AXIS
    off_line = np.linalg.norm(p - np.outer(y, AXIS), axis=1).max()
    turn = np.degrees(np.linalg.norm(Rotation.from_matrix(result.poses[:, SCAPHOID, :3, :3]).as_rotvec(), axis=1)).max()

    fine = np.linspace(0.0, t[-1], 40 * n_frames)
    ref = solve_ivp(rhs, (0.0, t[-1]), [0.0, 0.0], method="DOP853", rtol=1e-10, atol=1e-12, dense_output=True)
    assert ref.success
    y_ref = ref.sol(fine)[0]
    level = 0.5 * (y_ref.max() + y_ref.min())
    period_ref, hi_ref, lo_ref = oscillation(fine, y_ref, level)
    period, hi, lo = oscillation(t, y, level)
    amp_ref, amp = 0.5 * (hi_ref - lo_ref), 0.5 * (hi - lo)
    track = np.abs(y - ref.sol(t)[0]).max() / amp_ref

    period_err, amp_err = period / period_ref - 1.0, amp / amp_ref - 1.0
    summary = (
        f"{case}, mass_scale {mass_scale}: period {period * 1e3:.5f} ms vs {period_ref * 1e3:.5f} ms "
        f"({100 * period_err:+.4f} %), amplitude {amp:.5f} vs {amp_ref:.5f} mm ({100 * amp_err:+.4f} %), "
        f"track {100 * track:.3f} %, off line {off_line:.1e} mm, turn {turn:.1e}°"
    )
    print(summary)
    assert abs(period_err) < 0.01, summary
    assert abs(amp_err) < 0.01, summary
    assert track < 0.01, summary
    assert off_line < 1e-6 and turn < 1e-6, summary
    assert amp_ref > 0.1, summary  # a real oscillation, not a wobble


# --------------------------------------------------------------------------- 2. contact patches

THICKNESS_MM = 2.0  # total cartilage thickness of both layers
SPHERE_R_MM = 10.0
LAWS = {
    "fitted Mooney-Rivlin": fit_contact_law().law.as_array(),
    "hand-set stiffening": np.array([0.04, 0.12, 10.0, 30.0, 90.0]),
}


def pressed(patch, span_mm: float, law, load_n: float):
    """The capitate's `patch` (pair lunocapitate) pushed along +y by `load_n` onto the lunate,
    a rigid half-space y >= 0 (immovable: mass 0); the capitate's rotation held at identity."""
    grid = syn.half_space_grid([-span_mm, -3.0, -span_mm], [span_mm, 3.0, span_mm], 0.5, [0, 0, 0], [0, -1, 0])
    com = np.array([[0, 40, 0], [30, 40, 0], [-30, 40, 0], [0, 12, 0], [0, -12, 0]], float)
    mass = np.array([0.0, 0.0, 2e-6, 0.0, 4e-6])
    inertia = np.array([syn.box_inertia(2e-6, (10, 10, 10))] * 5)
    model = syn.model(mass=mass, com=com, inertia=inertia, law=law, grids={LUNATE: grid}, patches={LUNOCAPITATE: patch})
    settings = replace(SolverSettings(), settle_steps=3000)
    if "compressive_load_n" in _FIELDS:  # the load as a solver setting
        driver = idealized(model, flexion_deg=0.0, extension_deg=0.0, n_frames=3, direction="axial")
        settings = replace(settings, compressive_load_n=load_n)
    else:  # the load as part of the driver
        driver = idealized(model, flexion_deg=0.0, extension_deg=0.0, n_frames=3, load_n=load_n, direction="axial")
    result = simulate(model, design.population(), driver, settings)
    assert result.ok, result.message
    np.testing.assert_allclose(result.poses[:, CAPITATE, :3, :3], np.tile(np.eye(3), (3, 1, 1)), atol=1e-12)
    return result.contact[-1, LUNOCAPITATE], result.poses[-1, CAPITATE, :3, 3]


def sphere_force(law, d0):
    """Elastic-foundation force (N) of a rigid sphere (radius R) pressed d0 (mm) into a layer of thickness h:
    F = ∫ p(δ(r)/h) 2πr dr, δ(r) = d0 − R + √(R² − r²); with r dr = −(R − d0 + δ) dδ,
    F = 2π ∫_0^d0 p(δ/h) (R − d0 + δ) dδ."""
    h, R = THICKNESS_MM, SPHERE_R_MM
    breaks = [h * e for e in law[:2] if h * e < d0]
    return (
        2
        * np.pi
        * quad(
            lambda d: trilinear(law, d / h) * (R - d0 + d),
            0.0,
            d0,
            points=breaks or None,
            epsabs=0.0,
            epsrel=1e-13,
            limit=200,
        )[0]
    )


def check(name, got, want, rel):
    err = got / want - 1.0
    print(f"  {name}: {got:.6g} vs {want:.6g} ({100 * err:+.4f} %)")
    assert abs(err) < rel, (name, got, want)


@pytest.mark.parametrize("law_name", list(LAWS))
def test_flat_patch_matches_uniform_pressure(law_name):
    """A flat 4 × 4 mm cartilage patch (256 samples, all of total thickness h = 2 mm) pushed
    by the idealized driver's compressive load onto a rigid flat half-space reaches the
    closed form of a uniform elastic foundation: p = F / A everywhere, so mean = peak = F / A,
    contact area A, force F, and the approach δ = h·law⁻¹(F / A). The load puts the strain
    in the law's upper segments. Tolerance 2 % on each."""
    law = LAWS[law_name]
    strain = 1.6 * law[0] if law_name.startswith("fitted") else 0.2
    area = 16.0
    pressure = trilinear(law, strain)
    load = pressure * area
    patch = syn.square_patch([0.0, 0.0, 0.0], 2.0, 0.25, THICKNESS_MM, [0.0, 1.0, 0.0])
    contact, shift = pressed(patch, 4.0, law, load)
    delta = THICKNESS_MM * brentq(lambda e: trilinear(law, e) - pressure, 0.0, 1.0, xtol=1e-15)
    print(f"{law_name}, flat, load {load:.1f} N:")
    check("mean pressure MPa", contact[MEAN], load / area, 0.02)
    check("peak pressure MPa", contact[PEAK], load / area, 0.02)
    check("area mm²", contact[AREA], area, 0.02)
    check("force N", contact[FORCE], load, 0.02)
    check("approach mm", shift[1], delta, 0.02)
    assert abs(shift[0]) < 1e-6 and abs(shift[2]) < 1e-6, shift


@pytest.mark.parametrize("law_name", list(LAWS))
def test_spherical_cap_matches_elastic_foundation(law_name):
    """A spherical cap (R = 10 mm, samples on a 0.1 mm x–z lattice carrying their projected
    area, total thickness h = 2 mm) pushed by the idealized driver's compressive load onto a
    rigid flat half-space, against the closed-form elastic foundation of the tri-linear law:
    F(d0) = ∫ p(δ(r)/h) 2πr dr over the contact circle with δ(r) = d0 − R + √(R² − r²)
    (exact sphere), solved for d0 at the applied load; peak = p(d0/h), contact area
    π(2R d0 − d0²), mean = F / area. The load drives the apex strain past e2 (all three
    segments of the law in play). ~26 samples across the contact radius keep the lattice's
    area-counting error well below the 2 % tolerance on mean, peak, area, force and d0."""
    law = LAWS[law_name]
    d0_target = THICKNESS_MM * 1.2 * law[1]
    load = sphere_force(law, d0_target)
    d0 = brentq(lambda d: sphere_force(law, d) - load, 1e-6, 2.0, xtol=1e-14)
    area = np.pi * (2 * SPHERE_R_MM * d0 - d0 * d0)
    a = np.sqrt(area / np.pi)
    patch = syn.spherical_cap([0.0, 0.0, 0.0], SPHERE_R_MM, a + 0.4, 0.1, THICKNESS_MM)
    contact, shift = pressed(patch, a + 1.5, law, load)
    print(f"{law_name}, sphere, load {load:.1f} N, contact radius {a:.3f} mm, {len(patch.points)} samples:")
    check("mean pressure MPa", contact[MEAN], load / area, 0.02)
    check("peak pressure MPa", contact[PEAK], trilinear(law, d0 / THICKNESS_MM), 0.02)
    check("area mm²", contact[AREA], area, 0.02)
    check("force N", contact[FORCE], load, 0.02)
    check("approach mm", shift[1], d0, 0.02)
    assert abs(shift[0]) < 1e-6 and abs(shift[2]) < 1e-6, shift


# --------------------------------------------------------------------------- 3. frame invariance

MOVES = {  # (axis, quarter turns), translation mm
    "90° about x": ((0, 1), [7.3, -41.7, 12.9]),
    "180° about y": ((1, 2), [-23.1, 5.55, 0.7]),
    "270° about z": ((2, 3), [0.35, 17.0, -60.2]),
}


def capitate_motion(model):
    """Four capitate transforms (neutral → frame): turns of up to 25° about its centre of mass
    about oblique axes, with sub-millimetre translations."""
    c = model.com[CAPITATE]
    rv = np.radians([[0, 0, 0], [2, 3, 12], [-1, 2, 25], [3, -4, -15]])
    T = np.tile(np.eye(4), (len(rv), 1, 1))
    T[:, :3, :3] = Rotation.from_rotvec(rv).as_matrix()
    T[:, :3, 3] = c - T[:, :3, :3] @ c + np.array([[0, 0, 0], [0.2, -0.1, 0.1], [0.3, 0.1, -0.2], [-0.2, 0.2, 0.1]])
    return T


def homogeneous(Q, t):
    G = np.eye(4)
    G[:3, :3], G[:3, 3] = Q, t
    return G


@pytest.mark.parametrize("move", list(MOVES))
def test_moved_model_is_the_same_geometry(p1, move):
    """The test's own `transformed` (reference for the invariance test): each moved grid,
    interpolated tri-linearly by SciPy at moved points, equals the original at the original
    points (1e-5 mm, float32 values); centres of mass and inertia move as rigid-body
    quantities."""
    (axis, turns), t = MOVES[move]
    Q = syn.rotation_90(axis, turns)
    moved = syn.transformed(p1, Q, t)
    rng = np.random.default_rng(0)
    for b in (RADIUS, SCAPHOID, LUNATE, CAPITATE):

        def interpolator(m):
            n, o, h = m.grid_shape[b], m.grid_origin[b], m.grid_spacing[b]
            axes = [o[i] + h * np.arange(n[i]) for i in range(3)]
            return RegularGridInterpolator(axes, m.grid(BONES[b]).astype(float)), axes

        f, axes = interpolator(p1)
        g, _ = interpolator(moved)
        q = np.stack([rng.uniform(ax[0], ax[-1], 2000) for ax in axes], axis=1)
        np.testing.assert_allclose(g(q @ Q.T + t), f(q), atol=1e-5, err_msg=BONES[b])
    np.testing.assert_allclose(moved.com, p1.com @ Q.T + t, atol=1e-12)
    np.testing.assert_allclose(moved.inertia, Q @ p1.inertia @ Q.T, rtol=1e-12, atol=0)


@pytest.mark.parametrize("move", list(MOVES))
def test_rigidly_moved_model_gives_the_same_relative_kinematics(p1, move):
    """P1 (ground-truth design, the diagonal mass, experimental driver) moved rigidly by G
    (a turn about a coordinate axis, so the axis-aligned float32 grids are permuted exactly,
    plus a translation) with the capitate driven by G T G⁻¹: the scaphoid, lunate and
    capitate poses relative to the radius, mapped back (G⁻¹ P G), match the unmoved run's
    within 1e-5 mm (centre of mass) and 1e-4°; contact outputs and bundle forces within
    1e-5 of their largest values. Only float64 round-off differs between the runs (with the free
    radial column and the TFCC's soft layer it reaches 3e-6 mm and 3e-5°; five bodies kept it under
    1e-6 mm and 1e-5°). The block mass (the default solver) takes its path from round-off too: its
    rebuilds and FIRE's restarts fall on other steps (340 steps against 335), so its answers agree only
    within the equilibrium tolerance (measured 5e-4 mm, 6e-3°); this test is of the physics' frame
    independence, so it runs the diagonal mass."""
    (axis, turns), t = MOVES[move]
    Q = syn.rotation_90(axis, turns)
    G = homogeneous(Q, t)
    G_inv = np.linalg.inv(G)
    moved = syn.transformed(p1, Q, t)
    T = capitate_motion(p1)
    dsg = truth("P1")
    diagonal = SolverSettings().diagonal()
    a = simulate(p1, dsg, experimental(p1, T), diagonal)
    b = simulate(moved, dsg, experimental(moved, G @ T @ G_inv), diagonal)
    assert a.ok and b.ok, (a.message, b.message)
    back = G_inv @ b.poses @ G
    scaphoid_turn = np.degrees(np.linalg.norm(Rotation.from_matrix(a.poses[:, SCAPHOID, :3, :3]).as_rotvec(), axis=1))
    assert scaphoid_turn.max() > 5.0, scaphoid_turn  # the carpus really moves
    worst = {}
    for bone in (SCAPHOID, LUNATE, CAPITATE):
        rel_a = np.linalg.inv(a.poses[:, RADIUS]) @ a.poses[:, bone]
        rel_b = np.linalg.inv(back[:, RADIUS]) @ back[:, bone]
        c = p1.com[bone]
        shift = np.linalg.norm(
            np.einsum("fij,j->fi", rel_a[:, :3, :3] - rel_b[:, :3, :3], c) + rel_a[:, :3, 3] - rel_b[:, :3, 3], axis=1
        ).max()
        turn = np.degrees(
            np.linalg.norm(
                Rotation.from_matrix(np.swapaxes(rel_a[:, :3, :3], 1, 2) @ rel_b[:, :3, :3]).as_rotvec(), axis=1
            )
        ).max()
        worst[BONES[bone]] = (shift, turn)
    contact = np.abs(a.contact - b.contact).max() / np.abs(a.contact).max()
    bundle = np.abs(a.bundle_force - b.bundle_force).max() / np.abs(a.bundle_force).max()
    summary = (
        f"{move}: "
        + ", ".join(f"{k} {s:.1e} mm {r:.1e}°" for k, (s, r) in worst.items())
        + f", contact {contact:.1e}, bundles {bundle:.1e} (relative)"
    )
    if hasattr(a, "steps"):
        summary += f", steps {a.steps.sum()} vs {b.steps.sum()}"
    print(summary)
    for shift, turn in worst.values():
        assert shift < 1e-5 and turn < 1e-4, summary
    assert contact < 1e-5 and bundle < 1e-5, summary
