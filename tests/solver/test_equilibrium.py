"""The quasi-static Newton reference (`equilibrium.nearest`) against closed-form equilibria and the explicit solver."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq
from test_verification import EPSILON_L, OSCILLATORS, oscillator, undamped

from wrist_env import design
from wrist_env.anatomy.tendons import resultant_direction
from wrist_env.ligaments import LIGAMENT_NAMES
from wrist_env.model import CAPITATE
from wrist_env.participants import registry
from wrist_env.solver.drivers import AXIAL, experimental, idealized, loaded
from wrist_env.solver.equilibrium import nearest, tangent_stiffness
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import simulate

SCAPHOID = 2
AXIS = np.array([1.0, 2.0, 2.0]) / 3.0
CENTRE = np.array([3.0, -1.0, 2.0])


def tension(K, strain):
    """Blankevoort tension (N), DESIGN.md."""
    if strain <= 0.0:
        return 0.0
    return K * strain * strain / (4 * EPSILON_L) if strain <= 2 * EPSILON_L else K * (strain - EPSILON_L)


def two_bundles_mid_oscillation():
    """A free scaphoid between two opposed fibre bundles on one line through its centre of mass, left
    mid-oscillation by a few undamped steps: (model, design, driver, settings, run, fibre origins a (mm
    along the line), zero-load lengths l0 (mm), scales K (N))."""
    fib, materials = OSCILLATORS["two bundles opposed"]
    model = oscillator(fib)
    vector = design.population().vector.copy()
    for lig, (k, r) in materials.items():
        vector[lig], vector[len(LIGAMENT_NAMES) + lig] = k, r
    dsg = design.Design.from_vector(vector)
    a = np.array([p for _, p in fib])
    l0 = np.array([abs(p) / materials[g][1] for g, p in fib])
    K = np.array([materials[g][0] * l for (g, _), l in zip(fib, l0)])
    settings = replace(
        undamped(SolverSettings().diagonal()),
        dt_s=1e-6,
        settle_steps=0,
        move_steps=0,
        ramp_steps=0,
        min_hold_steps=7,
        max_hold_steps=7,
        inertia_scale=1.0,
        max_disp_mm=1e3,
    )
    driver = experimental(model, np.tile(np.eye(4), (2, 1, 1)))
    result = simulate(model, dsg, driver, settings)
    assert result.ok
    return model, dsg, driver, settings, result, a, l0, K


def test_two_opposed_bundles_reach_the_closed_form_equilibrium():
    """The two opposed bundles (`two_bundles_mid_oscillation`): the Newton reference lands where the two
    tensions balance (brentq on the force balance written here), to 1e-6 mm, with no net force left."""
    model, dsg, driver, settings, result, a, l0, K = two_bundles_mid_oscillation()

    def net(y):  # force along the line on the body at y
        return sum(-tension(Ki, abs(y - ai) / l0i - 1.0) * np.sign(y - ai) for ai, l0i, Ki in zip(a, l0, K))

    y_star = brentq(net, a.min() + 1e-3, a.max() - 1e-3)
    start = result.poses[-1, SCAPHOID, :3, 3] @ AXIS
    eq = nearest(model, dsg, driver, result, settings)
    y = eq.poses[-1, SCAPHOID, :3, 3] @ AXIS
    assert abs(start - y_star) > 0.05, "the explicit state must start away from equilibrium"
    assert abs(y - y_star) < 1e-6, (y, y_star)
    assert eq.residual[-1, 0] < 1e-6
    assert abs(eq.distance[-1, 0] - abs(start - y_star)) < 1e-6


def test_population_sweep_is_near_its_equilibrium(p1):
    """The explicit answer of P1's population sweep (3 frames) is within 0.1 mm and 0.5° of the
    equilibrium the Newton reference finds from it, which leaves less net force than the explicit run."""
    driver = idealized(p1, n_frames=3)
    result = simulate(p1, design.population(), driver)
    eq = nearest(p1, design.population(), driver, result)
    assert eq.distance[:, 0].max() < 0.1 and eq.distance[:, 1].max() < 0.5, eq.distance
    assert eq.residual[:, 0].max() < result.residual[:, 0].max(), (eq.residual, result.residual)


def test_tangent_stiffness_of_two_opposed_bundles_is_the_closed_form():
    """The two opposed bundles mid-way (`two_bundles_mid_oscillation`): along the line the stiffness is
    Σ T'(ε_i)/l0_i, across it the tensions' geometric stiffness Σ T_i/L_i (Blankevoort, DESIGN.md,
    written here), and nothing resists a rotation about the centre of mass."""
    model, dsg, driver, settings, result, a, l0, K = two_bundles_mid_oscillation()
    y = result.poses[-1, SCAPHOID, :3, 3] @ AXIS  # the centre of mass's shift along the line
    length = np.abs(y - a)
    strain = length / l0 - 1.0
    slope = np.where(strain <= 0.0, 0.0, np.where(strain <= 2 * EPSILON_L, K * strain / (2 * EPSILON_L), K))  # dT/dε
    assert np.all(strain > 0.0), strain  # both taut: the line's stiffness has both terms
    along = np.sum(slope / l0)
    across = np.sum([tension(Ki, e) / L for Ki, e, L in zip(K, strain, length)])

    s = tangent_stiffness(model, dsg, driver, result, frame=1, settings=settings)
    shift = s.stiffness[:3, :3]
    normal = np.cross(AXIS, [1.0, 0.0, 0.0])
    normal /= np.linalg.norm(normal)
    assert np.isclose(AXIS @ shift @ AXIS, along, rtol=1e-4), (AXIS @ shift @ AXIS, along)
    assert np.isclose(normal @ shift @ normal, across, rtol=1e-4), (normal @ shift @ normal, across)
    assert np.abs(s.stiffness[3:6, :]).max() < 1e-6 * along
    assert np.allclose(s.mass[:3, :3], model.mass[SCAPHOID] * settings.mass_scale * np.eye(3))


def test_population_trial_sits_in_a_stable_equilibrium_the_step_resolves(p1):
    """At a settled frame of P1's population calibration trial the free bones' condensed stiffness is
    nearly symmetric (the contact and ligament forces derive from energies) and positive definite (a
    stable equilibrium), and the default time step is below the explicit integrator's stability
    limit 2/ω_max of its stiffest mode."""
    driver = experimental(p1, registry.trial("P1", "calibrate").pose("capitate"))
    result = simulate(p1, design.population(), driver)
    s = tangent_stiffness(p1, design.population(), driver, result, frame=8)
    omega = s.frequencies()
    assert s.asymmetry < 0.1, s.asymmetry
    assert np.all(np.isfinite(omega)) and omega[0] > 0.0, omega
    assert SolverSettings().dt_s < 2.0 / omega[-1], (SolverSettings().dt_s, 2.0 / omega[-1])


def test_a_load_along_the_tendons_moves_the_distal_row_its_way_and_balances(p1):
    """At neutral under 100 N along the Erhart rig's tendon resultant (dorsal and radial of the radius'
    axis) the distal row sits, against the axial load, further along the load's off-axis part; the
    Newton reference, which applies the same force, finds the explicit answer within 0.1 mm."""
    tilted = resultant_direction("erhart2020")
    runs = {}
    for name, direction in (("axial", AXIAL), ("tendons", tilted)):
        driver = loaded(p1, [np.eye(3)], load_n=100.0, direction=direction)
        result = simulate(p1, design.population(), driver)
        assert result.ok, result.message
        runs[name] = (driver, result)
    shift = runs["tendons"][1].poses[0, CAPITATE, :3, 3] - runs["axial"][1].poses[0, CAPITATE, :3, 3]
    off_axis = tilted - (tilted @ np.array(AXIAL)) * np.array(AXIAL)
    assert shift @ off_axis / np.linalg.norm(off_axis) > 0.05, (shift, off_axis)
    driver, result = runs["tendons"]
    eq = nearest(p1, design.population(), driver, result)
    assert eq.distance[0, 0] < 0.1 and eq.distance[0, 1] < 0.5, eq.distance


def test_a_load_direction_must_be_a_finite_nonzero_vector(p1):
    assert np.allclose(loaded(p1, [np.eye(3)], 5.0, direction=(0.0, 2.0, 0.0)).resultant(0), (0.0, 5.0, 0.0))
    for bad in ((0.0, 0.0, 0.0), (np.nan, 1.0, 0.0), (1.0, 0.0), "sideways"):
        with pytest.raises(ValueError, match="load_direction"):
            loaded(p1, [np.eye(3)], 5.0, direction=bad)
