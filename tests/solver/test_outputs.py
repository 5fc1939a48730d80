"""Simulation outputs: the per-sample pressure map and the JSON-ready per-frame dict."""

import json

import numpy as np
import pytest

from wrist_env import design, ligaments
from wrist_env.model import BONES, N_BODIES, PAIR_BONES, PAIRS
from wrist_env.solver import arrays, forces
from wrist_env.solver.contact import sdf_lookup
from wrist_env.solver.drivers import idealized
from wrist_env.solver.outputs import pair_slice, pressure_map, result_to_dict
from wrist_env.solver.simulate import Result, prepare, simulate
from wrist_env.solver.step import State, new_work

RS = PAIRS.index("radioscaphoid")


@pytest.fixture(scope="module")
def sweep(p1):
    result = simulate(p1, design.population(), idealized(p1, n_frames=5))
    assert result.ok, result.message
    return result


def _state(model, pose_frame):
    R = np.ascontiguousarray(pose_frame[:, :3, :3])
    return R, np.ascontiguousarray(np.einsum("bij,bj->bi", R, model.com) + pose_frame[:, :3, 3])


def test_pressure_map_is_zero_exactly_out_of_contact(p1, sweep):
    """A sample has pressure iff it overlaps the other bone's grid (signed distance < 0), found
    here independently of the kernel: sample → world by its bone's pose → the grid bone's frame."""
    for f in (0, 2, 4):
        poses = sweep.poses[f]
        p = pressure_map(p1, poses)
        assert p.shape == (len(p1.sample_points),) and np.all(np.isfinite(p)) and np.all(p >= 0)
        for k, pair in enumerate(PAIRS):
            a, b = PAIR_BONES[k]
            s = pair_slice(p1, pair)
            world = p1.sample_points[s] @ poses[a, :3, :3].T + poses[a, :3, 3]
            local = (world - poses[b, :3, 3]) @ poses[b, :3, :3]  # inverse pose of the grid bone
            d = np.array(
                [
                    sdf_lookup(
                        p1.grid_values, p1.grid_offsets[b], p1.grid_shape[b], p1.grid_origin[b], p1.grid_spacing[b], q
                    )[0]
                    for q in local
                ]
            )
            np.testing.assert_array_equal(p[s] > 0, d < 0, err_msg=f"frame {f}, {pair}")
    assert (pressure_map(p1, sweep.poses[4])[pair_slice(p1, "radioscaphoid")] > 0).sum() >= 5


def test_pressure_map_sums_to_the_solver_contact_force_at_the_same_state(p1, sweep):
    """Area-weighted sums of the map equal the contact kernel's own per-pair force and area
    (all samples active) at the same poses, to rounding."""
    grids = arrays.grids(p1)
    system = prepare(p1).system._replace(grids=grids)  # the trilinear normals: no nodal normals
    n = len(p1.sample_points)
    for f in range(len(sweep.poses)):
        R, x = _state(p1, sweep.poses[f])
        nodes = np.zeros((0, 3))
        state = State(R, x, np.zeros((N_BODIES, 3)), np.zeros((N_BODIES, 3)), nodes, nodes)
        work = new_work(grids, nodes)  # its ref unset: every pair refills
        every = 1e9  # a band holding every sample
        forces.contact_forces(state, system.bodies.com0, system.grids, system.law, work, every, True, False)
        stats = work.stats
        assert work.n_active.sum() == n
        p = pressure_map(p1, sweep.poses[f])
        for k, pair in enumerate(PAIRS):
            s = pair_slice(p1, pair)
            force = np.sum(p[s] * p1.sample_area[s])
            np.testing.assert_allclose(force, stats[k, forces.C_FORCE], rtol=1e-9, atol=1e-12)
            np.testing.assert_allclose(p1.sample_area[s][p[s] > 0].sum(), stats[k, forces.C_AREA], rtol=1e-12)


def test_pressure_map_matches_the_result_contact_force(p1, sweep):
    """Against `Result.contact` itself: within 2 % (the kernel's forces lag its poses by one step)."""
    for f in range(len(sweep.poses)):
        p = pressure_map(p1, sweep.poses[f])
        s = pair_slice(p1, "radioscaphoid")
        np.testing.assert_allclose(np.sum(p[s] * p1.sample_area[s]), sweep.contact[f, RS, 3], rtol=2e-2)
        np.testing.assert_allclose(p[s].max(), sweep.contact[f, RS, 1], rtol=2e-2)


def test_pressure_map_matches_the_result_contact_force_exactly(p1, sweep):
    for f in range(len(sweep.poses)):
        p = pressure_map(p1, sweep.poses[f])
        s = pair_slice(p1, "radioscaphoid")
        np.testing.assert_allclose(np.sum(p[s] * p1.sample_area[s]), sweep.contact[f, RS, 3], rtol=1e-6)


def test_pressure_map_checks_the_pose_shape(p1):
    with pytest.raises(ValueError, match="shape"):
        pressure_map(p1, np.eye(4))


def test_result_to_dict_is_strict_json_with_every_output(p1, sweep):
    out = json.loads(json.dumps(result_to_dict(sweep, p1), allow_nan=False))
    assert out["status"] == 0 and out["ok"] and out["message"] == "ok" and out["n_frames"] == 5
    assert len(out["frames"]) == 5
    frame = out["frames"][4]
    assert frame["capitate_angle_deg"] == pytest.approx(-40.0)
    assert set(frame["poses"]) == set(BONES)
    np.testing.assert_allclose(frame["poses"]["lunate"], sweep.poses[4, BONES.index("lunate")])
    assert frame["rotation_deg"]["capitate"][0] == pytest.approx(-40.0, abs=1e-6)
    assert set(frame["contact"]) == set(PAIRS)
    rs = frame["contact"]["radioscaphoid"]
    assert rs == pytest.approx(
        dict(zip(("mean_pressure_mpa", "peak_pressure_mpa", "area_mm2", "force_n"), sweep.contact[4, RS]))
    )
    assert set(frame["ligament_force_n"]) == set(ligaments.ALL_LIGAMENT_NAMES)
    for key in ("kinetic_energy_nmm", "internal_energy_nmm"):
        assert np.isfinite(frame[key])
    assert set(frame["residual"]) == {"force_n", "moment_nmm"} and frame["steps"] > 0
    assert frame["settled"] is True


def test_result_to_dict_of_a_failed_run_has_nulls(p1, sweep):
    nan = lambda a: np.full_like(a, np.nan)  # noqa: E731
    failed = Result(
        nan(sweep.poses),
        nan(sweep.contact),
        nan(sweep.bundle_force),
        nan(sweep.energy),
        nan(sweep.residual),
        sweep.steps,
        np.zeros_like(sweep.settled),
        nan(sweep.membrane_nodes),
        np.full(5, np.nan),
        1,
        "failed: NaN in the state",
    )
    out = json.loads(json.dumps(result_to_dict(failed, p1), allow_nan=False))
    assert not out["ok"] and out["status"] == 1
    frame = out["frames"][0]
    assert frame["capitate_angle_deg"] is None and frame["contact"]["radiolunate"]["force_n"] is None
    assert frame["poses"]["scaphoid"][0][0] is None and frame["rotation_deg"]["lunate"] == [None, None, None]


def test_articulations_split_each_pair_by_the_bone_under_its_samples(p1, sweep):
    """Each pair's articulations (`ARTICULATIONS`) partition its samples: their forces add up to the
    pair's force at the same poses, and every sample lies on one of the named bones."""
    from wrist_env.model import ARTICULATIONS, BODY_PARTS
    from wrist_env.solver.outputs import articulation_forces, sample_parts

    poses = sweep.poses[2]
    split = articulation_forces(p1, poses)
    load = pressure_map(p1, poses) * p1.sample_area
    for pair in PAIRS:
        joints = [name for name, (p, _) in ARTICULATIONS.items() if p == pair]
        s = pair_slice(p1, pair)
        np.testing.assert_allclose(sum(split[j] for j in joints), load[s].sum(), rtol=1e-12, err_msg=pair)
        body = BONES[PAIR_BONES[PAIRS.index(pair)][0]]
        named = {BODY_PARTS[body].index(q) for j in joints for q in ARTICULATIONS[j][1]}
        assert set(np.unique(sample_parts(p1, pair))) <= named, pair
    assert split["scaphocapitate"] > 0 and split["lunocapitate"] > 0
    assert split["ulnocarpal"] > 0.0  # the TFCC: the lunate body bears on the ulnar head (issue 33)


def test_the_driven_bodys_load_adds_a_line_on_it_as_r_cross_f(p1):
    """`driven_body_load` at a turned and shifted capitate: one line of tension t at capitate point p
    along u adds t·u to the force and (R(p − c0)) × t·u to the moment about the capitate's centre of
    mass, the closed form of a force on a rigid body; a line on another body (the radial column) adds
    nothing to either."""
    from dataclasses import replace

    from scipy.spatial.transform import Rotation

    from wrist_env.model import CAPITATE, TRAPEZIUM
    from wrist_env.solver.drivers import Loads, loaded
    from wrist_env.solver.outputs import driven_body_load

    rng = np.random.default_rng(1)
    poses = np.tile(np.eye(4), (N_BODIES, 1, 1))
    poses[CAPITATE, :3, :3] = Rotation.from_rotvec([0.05, -0.1, 0.15]).as_matrix()
    poses[CAPITATE, :3, 3] = (0.2, 0.3, -0.1)
    nodes = p1.membrane_nodes
    point = p1.com[CAPITATE] + rng.normal(0.0, 6.0, 3)
    u = np.array([0.3, 0.9, -0.2])
    u /= np.linalg.norm(u)
    base = loaded(p1, [np.eye(3)], 0.0)

    def load(body, tension):
        line = Loads(np.array([body]), point[None], u[None], np.ones(1))
        return driven_body_load(
            p1, design.population(), replace(base, loads=line, load_n=np.array([tension])), poses, nodes
        )

    F0, M0 = load(CAPITATE, 0.0)
    F1, M1 = load(CAPITATE, 7.5)
    arm = poses[CAPITATE, :3, :3] @ (point - p1.com[CAPITATE])
    assert np.allclose(F1 - F0, 7.5 * u, atol=1e-12)
    assert np.allclose(M1 - M0, np.cross(arm, 7.5 * u), atol=1e-9)
    F2, M2 = load(TRAPEZIUM, 7.5)
    assert np.allclose(F2, F0, atol=1e-12) and np.allclose(M2, M0, atol=1e-9)
