"""The drivers' loads as lines of action (`drivers.Loads`): where each tendon pulls, and the force and
moment each line puts on its body."""

import numpy as np
import pytest

from wrist_env import design
from wrist_env.anatomy.tendons import load_tendons, model_lines
from wrist_env.model import BODY_PARTS, BONES, LUNATE
from wrist_env.solver import step
from wrist_env.solver.drivers import Loads, loaded, loads
from wrist_env.solver.simulate import prepare, stiffness


def test_each_tendon_pulls_the_body_of_the_carpal_it_loads_near_its_template_site(p1):
    """Every line of the Erhart rig is on the body holding its carpal (`tendons.CARPAL_OF`), pulls along
    the template tendon's direction, and sits within 3 mm of its template site (P1 is the template under
    a smooth warp of a few mm); the shares are the rig's tensions over their sum."""
    tendons = load_tendons("erhart2020")
    body, point, direction, share = model_lines(p1, "erhart2020")
    for k, carpal in enumerate(tendons.carpal):
        assert carpal in BODY_PARTS[BONES[body[k]]], (tendons.names[k], carpal, BONES[body[k]])
    assert np.array_equal(direction, tendons.direction)
    assert np.allclose(share, tendons.tension / tendons.tension.sum()) and np.isclose(share.sum(), 1.0)
    assert np.linalg.norm(point - tendons.point, axis=1).max() < 3.0
    assert tendons.carpal[tendons.names.index("FCU")] == "hamate"  # the pisohamate ligament (Standring 2005)


def test_a_line_adds_its_force_and_its_moment_about_the_centre_of_mass(p1):
    """One line of tension t at body point p along u adds t·u to its body's force and (R(p − c0) ) × t·u
    to its moment, at a rotated and shifted pose: the closed form of a force on a rigid body."""
    p = prepare(p1, mode=1)
    design_arrays = stiffness(p, design.population())
    rng = np.random.default_rng(0)
    R = np.tile(np.eye(3), (len(BONES), 1, 1))
    angle = 0.2
    R[LUNATE] = [[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]]
    x = p.bodies.com0.copy()
    x[LUNATE] += (0.3, -0.2, 0.1)
    point = p1.com[LUNATE] + rng.normal(0.0, 5.0, 3)
    u = np.array([0.2, 0.9, -0.3])
    u /= np.linalg.norm(u)
    line = Loads(np.array([LUNATE]), point[None], u[None], np.ones(1))
    driver = loaded(p1, [np.eye(3)], 12.0)
    with_line = type(driver)(driver.mode, driver.rotation, driver.com, driver.angle_deg, driver.load_n, line)

    def forces(tension):
        nodes = np.array(p1.membrane_nodes, dtype=np.float64)
        state = step.State(R.copy(), x.copy(), np.zeros_like(x), np.zeros_like(x), nodes, np.zeros_like(nodes))
        work = step.new_work(p.grids, nodes)
        load = with_line.kernel_load(0)._replace(tension=np.array([tension]))
        step.net_forces(state, work, p.system, design_arrays, load, True, True, p.settings.smooth_normals)
        return work.F.copy(), work.T.copy()

    F0, T0 = forces(0.0)
    F1, T1 = forces(12.0)
    f = 12.0 * u
    arm = R[LUNATE] @ (point - p1.com[LUNATE])
    assert np.allclose(F1[LUNATE] - F0[LUNATE], f, atol=1e-12)
    assert np.allclose(T1[LUNATE] - T0[LUNATE], np.cross(arm, f), atol=1e-9)
    others = [b for b in range(len(BONES)) if b != LUNATE]
    assert np.array_equal(F1[others], F0[others]) and np.array_equal(T1[others], T0[others])


def test_lines_on_the_driven_capitate_act_as_their_resultant_and_the_columns_do_not(p1):
    """The Erhart lines on the capitate body, whose rotations the driver prescribes, end where their
    resultant on the capitate ends (their moments go to the driver), to 1e-3 mm and 1e-3 N: the same
    forces summed in another order change a hold's last steps, and a hold stops at a net force of
    0.01 N, which a soft direction (~10 N/mm) leaves 1e-3 mm from its balance; the radial column's lines (1st and 2nd rays) load a free body, so moving them to
    the capitate as a resultant changes the answer (the STT joint's force by more than 1 N), and so do
    the hamate's (4th and 5th rays, FCU through the pisiform: the triquetrohamate joint's force). Each run
    balances (every free body's net force under 0.05 N)."""
    from dataclasses import replace

    from wrist_env.model import HAMATE, PAIRS, TRAPEZIUM
    from wrist_env.solver.simulate import simulate

    rig = loaded(p1, [np.eye(3)], 100.0, direction="erhart2020")
    assert set(rig.loads.body) == {BONES.index("capitate"), TRAPEZIUM, HAMATE}
    joint = {TRAPEZIUM: PAIRS.index("scaphotrapezial"), HAMATE: PAIRS.index("triquetrohamate")}
    for body in (BONES.index("capitate"), TRAPEZIUM, HAMATE):
        keep = rig.loads.body == body
        share = rig.loads.share[keep] / rig.loads.share[keep].sum()
        part = replace(
            rig,
            loads=replace(
                rig.loads,
                body=rig.loads.body[keep],
                point=rig.loads.point[keep],
                direction=rig.loads.direction[keep],
                share=share,
            ),
        )
        total = part.resultant(0)
        resultant = loaded(p1, [np.eye(3)], float(np.linalg.norm(total)), direction=total)
        a, b = (simulate(p1, design.population(), d) for d in (part, resultant))
        assert a.ok and b.ok and a.settled.all() and a.residual[0, 0] < 0.05, (a.message, a.residual)
        if body in joint:
            j = joint[body]
            assert abs(a.contact[0, j, 3] - b.contact[0, j, 3]) > 1.0, (BONES[body], a.contact[0, j], b.contact[0, j])
        else:
            assert np.abs(a.poses - b.poses).max() < 1e-3
            assert np.abs(a.contact[..., 3] - b.contact[..., 3]).max() < 1e-3


def test_lines_need_a_known_rig(p1):
    with pytest.raises(ValueError, match="sideways"):
        loads(p1, "sideways")
    with pytest.raises(ValueError, match="rig"):
        model_lines(p1, "no_such_rig")


def test_the_capitohamate_joint_resists_a_shift_and_a_turn_in_its_plane_by_ritts_constraint(p1):
    """`forces.joint_forces` (the capitohamate joint's in-plane constraint, `ligaments.CH_JOINT_STIFFNESS` from
    Ritt 1996): the hamate moved by 0.5 mm along the joint's dorsopalmar axis, 0.3 mm proximodistally and
    0.2 mm along the normal, and turned 5 deg about the normal, gets back 30.8 N/mm × 0.5 and × 0.3 mm in
    the plane, nothing along the normal, and −3.18 N·m/rad × 5 deg about it plus the shift's lever; the
    capitate gets the opposite force and moment (about its own centre point)."""
    from scipy.spatial.transform import Rotation

    from wrist_env.ligaments import CH_JOINT_STIFFNESS
    from wrist_env.model import CAPITATE, HAMATE
    from wrist_env.solver.forces import joint_forces

    p = prepare(p1, mode=1)
    bod = p.bodies
    centre, axes = bod.joint_centre, bod.joint_axes
    assert np.allclose(axes @ axes.T, np.eye(3)) and axes[2, 2] > 0.8  # the normal is radioulnar
    R = np.tile(np.eye(3), (len(BONES), 1, 1))
    turn = np.radians(5.0)
    R[HAMATE] = Rotation.from_rotvec(turn * axes[2]).as_matrix()
    x = bod.com0.copy()
    shift = 0.5 * axes[0] + 0.3 * axes[1] + 0.2 * axes[2]
    # the hamate's centre point (its neutral place of the joint's centre) at centre + shift
    x[HAMATE] = centre + shift - R[HAMATE] @ (centre - bod.com0[HAMATE])
    state = step.State(R, x, np.zeros_like(x), np.zeros_like(x), np.zeros((0, 3)), np.zeros((0, 3)))
    work = step.new_work(p.grids, np.zeros((0, 3)))
    energy = joint_forces(state, bod, work, True)
    F, T = work.F, work.T
    k = CH_JOINT_STIFFNESS
    force = -(k[0] * 0.5 * axes[0] + k[1] * 0.3 * axes[1])
    np.testing.assert_allclose(F[HAMATE], force, atol=1e-9)
    np.testing.assert_allclose(F[CAPITATE], -force, atol=1e-9)
    lever_h = centre + shift - x[HAMATE]
    np.testing.assert_allclose(T[HAMATE], np.cross(lever_h, force) - k[5] * turn * axes[2], atol=1e-6)
    np.testing.assert_allclose(T[CAPITATE], np.cross(centre - x[CAPITATE], -force) + k[5] * turn * axes[2], atol=1e-6)
    assert energy == pytest.approx(0.5 * (k[0] * 0.25 + k[1] * 0.09 + k[5] * turn**2))
    assert k[0] == k[1] == pytest.approx(20 / 0.65)
    assert k[5] == pytest.approx(500 / np.radians(9.0)) and k[2] == k[3] == k[4] == 0.0
