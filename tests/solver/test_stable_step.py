"""The membrane's node mass keeps the explicit step stable for every RSC stiffness in the action box;
every frame says whether it settled."""

from dataclasses import replace

import numpy as np
import pytest

from wrist_env import design
from wrist_env.model import N_BODIES
from wrist_env.participants import registry
from wrist_env.solver import arrays
from wrist_env.solver.drivers import experimental
from wrist_env.solver.ligaments import EPSILON_L
from wrist_env.solver.membrane import membrane_forces, place_nodes
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import prepare, simulate, stiffness
from wrist_env.solver.step import State, Stiffness, new_work

pytestmark = pytest.mark.slow  # builds models or runs simulations/studies (minutes)

RSC_STIFFNESS = design.NAMES.index("RSC.stiffness")


def stiff_rsc() -> design.Design:
    """The population design with the RSC at the top of the action box (+3 SD), nothing torn."""
    action = np.r_[np.zeros(design.N_MATERIAL), np.ones(design.N_DESIGN - design.N_MATERIAL)]
    action[RSC_STIFFNESS] = 1.0
    return design.from_action(action)


def test_membrane_eigenvalue_matches_the_force_kernels_jacobian(p1):
    """The stiffest mode from the assembled axial stiffness equals the largest eigenvalue of the
    finite-difference Jacobian of `membrane_forces` on the free nodes, with every connector just into
    its linear region (where the tension adds a geometric stiffness of ~4 % of the axial one)."""
    p = prepare(p1)
    mem = p.membrane
    _, _, l0, K = arrays.design_arrays(p1, p.fibres, mem, stiff_rsc())
    m_l0 = mem.rest_length / (1.0 + 2.0 * EPSILON_L + 0.01)  # every connector into its linear region
    m_K = K / l0 * m_l0  # the same N/mm per connector
    R, x = np.tile(np.eye(3), (N_BODIES, 1, 1)), p1.com.copy()
    nodes = mem.rest.copy()
    place_nodes(R, x, p1.com, mem, nodes)
    free = np.flatnonzero(np.asarray(p1.membrane_bone) < 0)
    connectors = Stiffness(np.zeros(0), np.zeros(0), m_l0, m_K, 0.0)

    def forces(q):
        moved = nodes.copy()
        moved[free] += q.reshape(-1, 3)
        state = State(R, x, np.zeros((N_BODIES, 3)), np.zeros((N_BODIES, 3)), moved, np.zeros_like(moved))
        work = new_work(p.grids, moved)
        membrane_forces(state, p.bodies.com0, p.membrane, 0.0, connectors, work, False, True)  # no contact
        return work.node_force[free].ravel()

    h = 1e-6
    J = np.array([(forces(h * e) - forces(-h * e)) / (2 * h) for e in np.eye(3 * len(free))]).T
    numeric = np.linalg.eigvalsh(-(J + J.T) / 2)[-1]
    assembled = p.membrane_eigenvalue * np.max(m_K / m_l0)
    print(f"stiffest mode: assembled {assembled:.2f} N/mm, force kernels' Jacobian {numeric:.2f} N/mm")
    assert assembled == pytest.approx(numeric, rel=0.02)


def test_node_mass_is_raised_only_where_the_step_needs_it(p1):
    p = prepare(p1)
    population = stiffness(p, design.population())
    assert population.node_mass == SolverSettings().node_mass_t  # the population's runs unchanged
    stiff = stiffness(p, stiff_rsc())
    k_along = np.max(stiff.m_K / stiff.m_l0)
    omega = np.sqrt((p.membrane_eigenvalue * k_along + p.settings.membrane_contact_stiffness) / stiff.node_mass)
    assert stiff.node_mass > population.node_mass
    assert p.settings.dt * omega == pytest.approx(arrays.COURANT)


def test_a_stiff_rsc_settles_every_frame(p1):
    """With the nodes at `node_mass_t` whatever the design, the RSC's +3 SD design chattered on P1's
    calibration trial (9,823 steps, 8.8 N left on a free bone); with their mass raised every frame settles."""
    driver = experimental(p1, registry.trial("P1", "calibrate").pose("capitate"))
    s = SolverSettings().diagonal()  # the node mass as the diagonal mass's step needs it (no substeps)
    run = simulate(p1, stiff_rsc(), driver, s)
    assert run.ok, run.message
    assert run.steps[1:].max() < s.ramp_steps + s.max_hold_steps  # no frame ran out of hold steps
    assert np.max(run.residual[:, 0]) < 0.5  # N
    assert run.steps.sum() < 3000  # the population design takes ~2,200


def test_every_stiffness_at_the_top_of_the_box_settles_with_the_block_mass(p1):
    """All eleven stiffnesses at +3 SD at once, and the RSC alone: with the block mass
    (the defaults) every frame of P1's calibration trial settles."""
    from wrist_env.design import N_LIGAMENTS

    driver = experimental(p1, registry.trial("P1", "calibrate").pose("capitate"))
    everything = design.population().vector.copy()
    everything[:N_LIGAMENTS] = design.from_action(np.r_[np.ones(N_LIGAMENTS), np.zeros(16)]).vector[:N_LIGAMENTS]
    for dsg in (stiff_rsc(), design.Design.from_vector(everything)):
        run = simulate(p1, dsg, driver)
        assert run.ok and run.settled.all(), (run.message, run.settled)
        assert np.max(run.residual[:, 0]) < 0.5  # N


def test_settled_says_which_frames_ran_out_of_hold_steps(p1):
    driver = experimental(p1, registry.trial("P1", "calibrate").pose("capitate"))
    run = simulate(p1, design.population(), driver)
    assert run.settled.dtype == bool and run.settled.all()
    short = replace(SolverSettings(), min_hold_steps=1, max_hold_steps=2)  # no frame can settle in 2 steps
    cut = simulate(p1, design.population(), driver, short)
    assert cut.ok and not cut.settled.any()
    assert np.all(cut.steps[1:] == short.ramp_steps + short.max_hold_steps)
