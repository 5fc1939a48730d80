import itertools

import igl
import numpy as np
import pytest
import trimesh

from wrist_env.builder.fibres import Membrane, build_bundle, build_membrane, fibre_endpoints, pair_fibres
from wrist_env.errors import InputError


def _patch(centre, n, seed, half=(4.0, 0.0, 2.0)):
    rng = np.random.default_rng(seed)
    return np.asarray(centre, float) + rng.uniform(-1, 1, (n, 3)) * np.asarray(half)


def _rows_in(a, b):
    """Whether each row of a is exactly a row of b."""
    return np.array([np.any(np.all(b == x, axis=1)) for x in a])


@pytest.mark.parametrize("n_fibres", [7, 4, 3])
def test_fibre_endpoints_are_distinct_patch_points(n_fibres):
    patch = _patch([0, 0, 0], 150, seed=n_fibres)
    points, index = fibre_endpoints(patch, n_fibres, seed=1)
    assert points.shape == (n_fibres, 3) and index.shape == (n_fibres,)
    assert index.dtype == np.int64
    np.testing.assert_array_equal(points, patch[index])
    assert _rows_in(points, patch).all()
    assert len(np.unique(points, axis=0)) == n_fibres


def test_snapping_keeps_endpoints_distinct_when_centres_share_a_nearest_point():
    # Two tight clusters, one lone point each: K-means puts several centres per
    # cluster whose nearest patch point coincides.
    patch = np.array([[0, 0, 0], [0.01, 0, 0], [10, 0, 0], [10.01, 0, 0], [5, 5, 0]], float)
    points, index = fibre_endpoints(patch, 5, seed=0)
    assert sorted(index.tolist()) == [0, 1, 2, 3, 4]
    # duplicated rows count once
    dup = np.vstack([patch, patch[:2]])
    with pytest.raises(InputError, match="at least 6 distinct points, but holds 5"):
        fibre_endpoints(dup, 6, seed=0)


@pytest.mark.parametrize("n", [6, 7])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_kuhn_munkres_pairing_is_the_brute_force_minimum(n, seed):
    rng = np.random.default_rng(seed)
    origins = rng.uniform(-5, 5, (n, 3))
    insertions = rng.uniform(-5, 5, (n, 3)) + [0, 20, 0]
    perm = pair_fibres(origins, insertions)
    assert sorted(perm.tolist()) == list(range(n))
    total = np.linalg.norm(insertions[perm] - origins, axis=1).sum()
    dist = np.linalg.norm(origins[:, None] - insertions[None], axis=2)
    brute = min(dist[np.arange(n), list(p)].sum() for p in itertools.permutations(range(n)))
    assert total == pytest.approx(brute, rel=1e-12)


@pytest.mark.parametrize("n_fibres", [7, 4, 3])
def test_bundle_counts_reference_length_and_vertex_ids(n_fibres):
    o = _patch([0, 0, 0], 120, seed=10)
    i = _patch([1, 15, 0], 90, seed=11)
    o_ids, i_ids = np.arange(120) + 1000, np.arange(90) + 5000
    b = build_bundle("SLIL", o, i, n_fibres, seed=4, origin_vertex_ids=o_ids, insertion_vertex_ids=i_ids)
    assert b.name == "SLIL"
    assert b.origin.shape == b.insertion.shape == (n_fibres, 3)
    assert b.origin_index.dtype == b.insertion_index.dtype == np.int64
    np.testing.assert_array_equal(o[b.origin_index - 1000], b.origin)
    np.testing.assert_array_equal(i[b.insertion_index - 5000], b.insertion)
    assert b.reference_length_mm == pytest.approx(np.linalg.norm(b.insertion - b.origin, axis=1).mean(), rel=1e-12)
    # the stored pairing is already the minimum-length one
    np.testing.assert_array_equal(pair_fibres(b.origin, b.insertion), np.arange(n_fibres))


def test_same_seed_gives_the_same_bundle():
    o, i = _patch([0, 0, 0], 200, seed=1), _patch([0, 12, 3], 200, seed=2)
    a, b = build_bundle("DIC", o, i, 7, seed=3), build_bundle("DIC", o, i, 7, seed=3)
    for f in ("origin", "insertion", "origin_index", "insertion_index"):
        np.testing.assert_array_equal(getattr(a, f), getattr(b, f))
    assert a.reference_length_mm == b.reference_length_mm


def test_bundle_bad_input_raises():
    o, i = _patch([0, 0, 0], 5, seed=1), _patch([0, 12, 0], 50, seed=2)
    with pytest.raises(InputError, match=r"ligament RSL \(origin\).*at least 7 distinct points, but holds 5"):
        build_bundle("RSL", o, i, 7, seed=0)
    with pytest.raises(InputError, match=r"n_fibres >= 1.*n_fibres=0"):
        fibre_endpoints(i, 0, seed=0)
    with pytest.raises(InputError, match=r"shape \(n, 3\).*\(50, 2\)"):
        fibre_endpoints(i[:, :2], 3, seed=0)
    with pytest.raises(InputError, match=r"insertion_vertex_ids must have shape \(50,\).*\(49,\)"):
        build_bundle("RSL", i, i + [0, 10, 0], 3, seed=0, insertion_vertex_ids=np.arange(49))
    with pytest.raises(InputError, match=r"same shape.*\(3, 3\) and \(4, 3\)"):
        pair_fibres(np.zeros((3, 3)), np.zeros((4, 3)))


@pytest.fixture(scope="module")
def sphere():
    return trimesh.creation.icosphere(subdivisions=3, radius=8)


def _membrane_case(mesh, radius_centre, capitate_centre, n_along=9, n_across=5, lift=0.5):
    rp = _patch(radius_centre, 150, seed=21, half=(5.0, 0.3, 1.5))
    cp = _patch(capitate_centre, 150, seed=22, half=(5.0, 0.3, 1.5))
    return rp, cp, build_membrane(rp, cp, mesh, n_along=n_along, n_across=n_across, lift_mm=lift)


@pytest.mark.parametrize("n_along, n_across", [(9, 5), (6, 3)])
def test_membrane_grid_connectors_and_attachments(sphere, n_along, n_across):
    rp, cp, m = _membrane_case(sphere, [0, -11, 2], [0, 11, 2], n_along, n_across)
    assert isinstance(m, Membrane)
    assert m.shape == (n_along, n_across)
    assert m.nodes.shape == (n_along * n_across, 3)
    along, across = m.connectors[m.connector_kind == 0], m.connectors[m.connector_kind == 1]
    assert len(along) == (n_along - 1) * n_across
    assert len(across) == n_along * (n_across - 1)
    assert m.connectors.dtype == np.int64 and m.connector_kind.dtype == np.int8
    np.testing.assert_array_equal(np.abs(along[:, 1] - along[:, 0]), n_across)
    np.testing.assert_array_equal(across[:, 1] - across[:, 0], 1)
    assert m.radius_nodes.sum() == n_across and m.capitate_nodes.sum() == n_across
    assert not (m.radius_nodes & m.capitate_nodes).any()
    first, last = m.nodes[m.radius_nodes], m.nodes[m.capitate_nodes]
    np.testing.assert_array_equal(first, m.nodes[:n_across])
    assert _rows_in(first, rp).all() and _rows_in(last, cp).all()
    assert len(np.unique(first, axis=0)) == n_across and len(np.unique(last, axis=0)) == n_across
    length = np.linalg.norm(m.nodes[m.connectors[:, 1]] - m.nodes[m.connectors[:, 0]], axis=1)
    np.testing.assert_allclose(m.reference_length_mm, length, rtol=1e-12)


@pytest.mark.parametrize("lift", [0.5, 1.0])
def test_membrane_wraps_the_sphere_without_penetrating_it(sphere, lift):
    # The straight chords pass 2 mm from the centre (through the sphere); without
    # the push, the curves come within 0.08 mm (lift 0.5) and 0.32 mm (lift 1) of it.
    _, _, m = _membrane_case(sphere, [0, -9, 2], [0, 9, 2], lift=lift)
    free = ~(m.radius_nodes | m.capitate_nodes)
    s = igl.signed_distance(m.nodes[free], sphere.vertices, sphere.faces)[0]
    assert s.min() >= 0.9 * lift
    # independent check: the analytic sphere (the icosphere is inscribed, so its surface is inside)
    assert (np.linalg.norm(m.nodes[free], axis=1) - 8.0).min() >= 0.9 * lift - 0.15
    # the membrane rests on the waist: its middle row lies lift_mm off the sphere
    mid = m.nodes.reshape(m.shape + (3,))[m.shape[0] // 2]
    np.testing.assert_allclose(np.linalg.norm(mid, axis=1), 8.0 + lift, atol=0.1)


def test_membrane_clears_a_capsule():
    capsule = trimesh.creation.capsule(height=10.0, radius=3.0)  # axis z, centred at the origin
    capsule.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))  # axis x
    rp, cp, m = _membrane_case(capsule, [0, -6, 1], [0, 6, 1])
    free = ~(m.radius_nodes | m.capitate_nodes)
    s = igl.signed_distance(m.nodes[free], capsule.vertices, capsule.faces)[0]
    assert s.min() >= 0.9 * 0.5
    assert _rows_in(m.nodes[m.radius_nodes], rp).all() and _rows_in(m.nodes[m.capitate_nodes], cp).all()


def test_membrane_curves_do_not_cross(sphere):
    # Each patch's principal axis points either way depending on the seed
    # (seeds 0-3 give both signs); columns must stay in order from radius to capitate.
    rp = _patch([0, -11, 2], 150, seed=21, half=(5.0, 0.3, 1.5))
    for seed in range(4):
        cp = _patch([0, 11, 2], 150, seed=seed, half=(5.0, 0.3, 1.5))
        grid = build_membrane(rp, cp, sphere).nodes.reshape(9, 5, 3)
        assert np.all(np.diff(grid[0, :, 0]) * np.diff(grid[-1, :, 0]) > 0)


def test_membrane_bad_input_raises(sphere):
    rp, cp = _patch([0, -11, 2], 50, seed=1), _patch([0, 11, 2], 50, seed=2)
    with pytest.raises(InputError, match=r"n_along >= 3.*n_along=2"):
        build_membrane(rp, cp, sphere, n_along=2)
    with pytest.raises(InputError, match=r"n_across >= 2.*n_across=1"):
        build_membrane(rp, cp, sphere, n_across=1)
    with pytest.raises(InputError, match=r"lift_mm > 0.*lift_mm=-0.5"):
        build_membrane(rp, cp, sphere, lift_mm=-0.5)
    with pytest.raises(InputError, match=r"capitate_points must hold at least 5 distinct points, but holds 3"):
        build_membrane(rp, cp[:3], sphere)
