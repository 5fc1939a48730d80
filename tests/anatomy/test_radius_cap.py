"""The radius cap's envelope of balls against a brute-force evaluation over every point and node."""

import numpy as np

from wrist_env.anatomy.radius_cap import _ball_tops, offset_heightfield


def brute_tops(xs, zs, points, g):
    """max over points within g (in x–z) of y + sqrt(g² − d²) at every node; -inf where none."""
    X, Z = np.meshgrid(xs, zs, indexing="ij")
    d2 = (X.ravel()[:, None] - points[None, :, 0]) ** 2 + (Z.ravel()[:, None] - points[None, :, 2]) ** 2
    top = np.where(d2 < g * g * (1 - 1e-9), points[None, :, 1] + np.sqrt(np.maximum(g * g - d2, 0.0)), -np.inf)
    return top.max(axis=1)


def test_ball_tops_match_brute_force():
    rng = np.random.default_rng(3)
    points = rng.uniform([0, -2, 0], [6, 2, 9], size=(1000, 3))
    g, spacing = 1.5, 0.4
    lo = points[:, [0, 2]].min(axis=0) - g
    xs = np.arange(lo[0], points[:, 0].max() + g + spacing, spacing)
    zs = np.arange(lo[1], points[:, 2].max() + g + spacing, spacing)
    height = np.full(len(xs) * len(zs), -np.inf)
    cell = np.rint((points[:, [0, 2]] - lo) / spacing).astype(np.int64)
    _ball_tops(xs, zs, points, cell, g, int(np.ceil(g / spacing + 0.5)), height)
    assert np.isfinite(height).sum() > 0.75 * len(height)  # all but the dilated rim
    np.testing.assert_array_equal(height, brute_tops(xs, zs, points, g))


def test_one_ball_is_a_sphere_cap_and_off_footprint_is_nan():
    """A single point: inside the footprint the envelope is at least the ball's top (the crease fill only
    raises), its peak the ball's top over the point's own node, NaN beyond the dilated footprint."""
    point = np.array([[0.0, 5.0, 0.0]])
    xs, zs, height = offset_heightfield(point, point, joint_space_mm=1.5, spacing_mm=0.5)
    X, Z = np.meshgrid(xs, zs, indexing="ij")
    d2 = X**2 + Z**2
    cap = 5.0 + np.sqrt(np.clip(1.5**2 - d2, 0, None))
    defined = ~np.isnan(height)
    assert defined.any() and np.all(d2[defined] < 1.5**2)
    assert np.all(height[defined] >= cap[defined] - 1e-12)
    assert np.nanmax(height) == np.max(cap[defined])
