"""Contact samples (`builder.contact_samples`): seating the samples out of the opposing grids."""

import numpy as np

from wrist_env.builder.contact_samples import _seat_samples
from wrist_env.builder.sdf import DistanceGrid
from wrist_env.model import BONES, PAIR_BONES, PAIRS, offsets


def test_seating_moves_an_overclosed_sample_out_and_skips_a_pair_without_samples():
    """Every grid a half-space y < 0 (signed distance y): a sample 0.2 mm inside moves 0.2 mm out along
    its normal (back to y = 0), one outside stays, and the pairs left without samples (a model without the distal
    row: `pipeline.ABSENT_WITHOUT_DISTAL_ROW`) are skipped, not reduced over nothing."""
    y = np.arange(-4.0, 4.5, 0.5)
    values = np.broadcast_to(y[None, :, None], (len(y), len(y), len(y))).astype(np.float32)
    grid = DistanceGrid(np.array([-4.0, -4.0, -4.0]), 0.5, np.ascontiguousarray(values))
    grids = {BONES[b]: grid for b in np.unique(PAIR_BONES[:, 1])}
    sizes = np.zeros(len(PAIRS), np.int64)
    sizes[PAIRS.index("radiolunate")] = 2  # the others empty, the triquetrum's among them
    points = np.array([[0.0, -0.2, 0.0], [1.0, 0.5, 1.0]])
    normals = np.array([[0.0, -1.0, 0.0], [0.0, -1.0, 0.0]])  # the sample bone's outward normal: towards the grid
    seated, worst = _seat_samples(points, normals, offsets(sizes), grids)
    np.testing.assert_allclose(seated, [[0.0, 0.0, 0.0], [1.0, 0.5, 1.0]], atol=1e-6)
    assert abs(worst - 0.2) < 1e-6
