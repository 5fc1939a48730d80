"""The subcycled membrane (`membrane`) and the secant predictor (`predictor`): their forces and moves
against what they stand for, and the preconditioned solver's runs with them."""

from collections import namedtuple

import numpy as np
from scipy.spatial.transform import Rotation

from wrist_env import design
from wrist_env.model import CAPITATE, FREE, N_BODIES
from wrist_env.solver.drivers import experimental, idealized
from wrist_env.solver.membrane import _gaps, _substep_forces, membrane_forces, new_scratch, place_nodes, substep
from wrist_env.solver.predictor import MAX_RATIO, capitate_move, history, predict, record
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import prepare, simulate, stiffness
from wrist_env.solver.step import State, new_work

PRECONDITIONED = SolverSettings()


def _shaken_neutral(model, shake_mm, seed):
    """P1's settled neutral state under the preconditioned settings, the free nodes shaken by up to
    `shake_mm`: (R, x, nodes, free-node mask, prepared arrays, design arrays, the membrane's forces)."""
    driver = experimental(model, np.tile(np.eye(4), (2, 1, 1)))
    result = simulate(model, design.population(), driver)
    p = prepare(model, PRECONDITIONED, driver.mode)
    s = stiffness(p, design.population())
    pose = result.poses[-1]
    R = np.ascontiguousarray(pose[:, :3, :3])
    x = np.ascontiguousarray(np.einsum("bij,bj->bi", R, model.com) + pose[:, :3, 3])
    nodes = np.ascontiguousarray(result.membrane_nodes[-1]).copy()
    free = np.asarray(model.membrane_bone) < 0
    nodes[free] += np.random.default_rng(seed).uniform(-shake_mm, shake_mm, (free.sum(), 3))
    place_nodes(R, x, model.com, p.membrane, nodes)

    def exact():
        work = new_work(p.grids, nodes)
        k = p.settings.membrane_contact_stiffness
        membrane_forces(_state(R, x, nodes), p.bodies.com0, p.membrane, k, s, work, False, True)
        return work.node_force

    return R, x, nodes, free, p, s, exact


def _state(R, x, nodes, nv=None):
    """A `step.State` at rest at (R, x, nodes) (nv: the nodes' velocities, zeros unless given)."""
    nv = np.zeros_like(nodes) if nv is None else nv
    return State(R, x, np.zeros((N_BODIES, 3)), np.zeros((N_BODIES, 3)), nodes, nv)


def test_a_substep_feels_the_force_kernels_membrane_forces(p1):
    """On P1's settled neutral state with the free nodes shaken by up to 0.3 mm (some pressed into the
    scaphoid, connectors taut and slack): the substep's forces on the free nodes equal
    `membrane.membrane_forces`' to rounding, so the subcycled nodes settle where the solver's own forces
    balance (a node is looked up where gap − √3·travel < 0: here every travel is 0)."""
    R, x, nodes, free, p, s, exact = _shaken_neutral(p1, 0.3, 0)
    gap, travel = np.zeros(len(nodes)), np.zeros(len(nodes))
    _gaps(_state(R, x, nodes), p.system, gap, travel)
    force = np.zeros_like(nodes)
    _substep_forces(_state(R, x, nodes), p.system, s, gap, travel, force, True)
    assert (gap < 0).sum() > 0 and np.abs(exact()[free]).max() > 0.1
    np.testing.assert_allclose(force[free], exact()[free], rtol=1e-12, atol=1e-12)


def test_substeps_relax_the_nodes_to_their_equilibrium(p1):
    """The bones held at P1's settled neutral state and the free nodes shaken by 0.2 mm: 300 steps of
    substeps bring the nodes back to a balance of `membrane.membrane_forces` (largest free-node force below
    1e-3 N from over 1 N): the damping takes the shake's energy out, it does not pump it."""
    R, x, nodes, free, p, s, exact = _shaken_neutral(p1, 0.2, 1)
    before = np.abs(exact()[free]).max()
    state, scratch = _state(R, x, nodes), new_scratch(nodes)
    for _ in range(300):
        substep(state, p.system, s, scratch, True)
    after = np.abs(exact()[free]).max()
    assert before > 1.0 and after < 1e-3, (before, after)


def _rigid_path(t):
    """Rotations (n_bodies, 3, 3) and centres (n_bodies, 3) mm on a screw path: each body turns 0.05 rad
    per unit t about its own axis and moves 0.3 mm per unit t."""
    axes = np.array(
        [[0, 0, 1.0], [1.0, 0, 0], [0, 1.0, 0], [1.0, 1.0, 0], [0, 1.0, 1.0], [1.0, 0, 1.0], [1.0, 1.0, 1.0]]
    )[:N_BODIES]
    R = np.stack([Rotation.from_rotvec(0.05 * t * a / np.linalg.norm(a)).as_matrix() for a in axes])
    x = np.arange(3.0 * N_BODIES).reshape(N_BODIES, 3) + 0.3 * t * axes
    return R, x


_Membrane = namedtuple("Membrane", "bone")(np.array([0, -1, -1, 4]))
_LOADED = namedtuple("Settings", "driver")(1)  # the loaded driver: the capitate's centre is free


def test_the_secant_predictor_continues_a_screw_path_exactly():
    """Two equilibria on a screw path (constant turn and shift per unit capitate move): the predictor
    puts the free bodies and nodes where the path goes next, for a next move 1.5× the last (to rounding),
    caps the extrapolation at MAX_RATIO, zeroes the velocities, and leaves the fixed and driven bodies and
    the attached nodes alone."""
    st = _LOADED
    nodes0 = np.zeros((4, 3))
    h = history(N_BODIES, nodes0)
    for t in (0.0, 1.0):
        R, x = _rigid_path(t)
        record(h, R, x, nodes0 + t * np.array([0.1, 0.2, 0.3]), move=2.0)
    for move, t_next in ((3.0, 2.5), (100.0, 1.0 + MAX_RATIO)):
        R, x = _rigid_path(1.0)
        nodes = nodes0 + np.array([0.1, 0.2, 0.3])
        v, w, nv = np.ones((N_BODIES, 3)), np.ones((N_BODIES, 3)), np.ones((4, 3))
        assert predict(h, State(R, x, v, w, nodes, nv), _Membrane, st, move)
        R_expect, x_expect = _rigid_path(t_next)
        for b in FREE:
            np.testing.assert_allclose(R[b], R_expect[b], atol=1e-12)
            np.testing.assert_allclose(x[b], x_expect[b], atol=1e-12)
        np.testing.assert_allclose(x[CAPITATE], x_expect[CAPITATE], atol=1e-12)
        np.testing.assert_allclose(R[CAPITATE], _rigid_path(1.0)[0][CAPITATE])  # driven: its rotation stays
        np.testing.assert_allclose(x[:2], _rigid_path(1.0)[1][:2])  # radius and ulna: fixed
        np.testing.assert_allclose(nodes[1:3], t_next * np.tile([0.1, 0.2, 0.3], (2, 1)), atol=1e-12)
        np.testing.assert_allclose(nodes[[0, 3]], np.tile([0.1, 0.2, 0.3], (2, 1)))  # attached: not moved
        assert not v.any() and not w.any() and not nv.any()


def test_the_predictor_needs_two_equilibria_and_a_moving_capitate():
    st = _LOADED
    h = history(N_BODIES, np.zeros((4, 3)))
    R, x = _rigid_path(0.0)
    state = State(R, x, np.zeros((N_BODIES, 3)), np.zeros((N_BODIES, 3)), np.zeros((4, 3)), np.zeros((4, 3)))
    assert not predict(h, state, _Membrane, st, 1.0)
    record(h, R, x, np.zeros((4, 3)), 1.0)
    assert not predict(h, state, _Membrane, st, 1.0)
    record(h, R, x, np.zeros((4, 3)), 0.0)  # the last stage held the capitate still: no direction
    assert not predict(h, state, _Membrane, st, 1.0)
    assert np.isclose(capitate_move(np.array([0.0, 0.1, 0.0]), np.array([3.0, 4.0, 0.0])), 1.0 + 5.0)


def test_the_predicted_sweep_settles_every_frame_on_the_diagonal_mass_answer(p1):
    """P1's population sweep under the default solver (block mass, predictor, subcycled membrane): every
    frame settles within 0.02 mm and 0.15° of the diagonal mass's answer, and frames 2 on (the ones
    predicted) take fewer steps than without the predictor."""
    from dataclasses import replace

    from wrist_env.solver.equilibrium import distance

    driver = idealized(p1)
    default = simulate(p1, design.population(), driver, SolverSettings().diagonal())
    predicted = simulate(p1, design.population(), driver, PRECONDITIONED)
    plain = simulate(p1, design.population(), driver, replace(PRECONDITIONED, predict=False))
    assert predicted.ok and predicted.settled.all(), predicted.message
    d = distance(default.poses, predicted.poses, p1.com).max(axis=0)
    assert d[0] < 0.02 and d[1] < 0.15, d
    assert predicted.steps[2:].sum() < plain.steps[2:].sum(), (predicted.steps, plain.steps)


def test_a_frame_run_alone_from_the_previous_answer_lands_on_the_same_answer(p1):
    """`simulate_frame`: P1's population trial, frame 6 run alone from the default run's frame 5 (its poses
    and membrane nodes, at rest) lands within 0.01 mm and 0.1° of that run's frame 6, by either solver;
    frame 0 (nothing before it) is refused."""
    import pytest

    from wrist_env.participants import registry
    from wrist_env.solver.equilibrium import distance
    from wrist_env.solver.simulate import simulate_frame

    driver = experimental(p1, registry.trial("P1", "calibrate").pose("capitate"))
    run = simulate(p1, design.population(), driver)
    for settings in (SolverSettings().diagonal(), PRECONDITIONED):
        alone = simulate_frame(p1, design.population(), driver, 6, run.poses[5], run.membrane_nodes[5], settings)
        assert alone.ok and alone.settled[1] and np.isnan(alone.poses[0]).all()
        d = distance(alone.poses[1:], run.poses[6:7], p1.com)[0]
        assert d[0] < 0.01 and d[1] < 0.1, d
    with pytest.raises(ValueError, match="frame must be in 1..14"):
        simulate_frame(p1, design.population(), driver, 0, run.poses[0], run.membrane_nodes[0])
