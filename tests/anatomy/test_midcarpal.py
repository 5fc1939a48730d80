"""The distal row's seating: parallel midcarpal joint spaces (Gilula 1979), reproducible from myo-sim."""

import numpy as np
import pytest
import trimesh

from wrist_env.anatomy import midcarpal
from wrist_env.anatomy.template import JOINT_SPACE_MM, load_template, oriented_parts


def _template_parts():
    parts = load_template((20.0, 10.0), True).parts
    return {b: trimesh.Trimesh(s.vertices, s.faces, process=False) for b, s in parts.items()}


def test_seated_facets_are_nearly_parallel():
    before = midcarpal.facet_gaps(oriented_parts()[0])
    after = midcarpal.facet_gaps(_template_parts())
    # myo-sim as assembled: capitolunate 0.52 mm, scaphotrapezial 2.38 mm
    assert before.min() < 0.6 and before.max() > 2.3
    assert np.all(np.abs(after - JOINT_SPACE_MM) < 0.3), after
    assert np.ptp(after) < 0.5 * np.ptp(before)


def test_the_distal_row_moves_as_one_rigid_unit():
    T = midcarpal.read_seat()
    assert np.allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-9)
    assert np.isclose(np.linalg.det(T[:3, :3]), 1.0)
    raw, _ = oriented_parts()
    parts = _template_parts()
    for b in midcarpal.DISTAL_ROW:
        # each distal-row bone is its myo-sim mesh under the one transform (up to the RCS origin shift)
        shift = parts[b].vertices - (raw[b].vertices @ T[:3, :3].T + T[:3, 3])
        assert np.allclose(shift, shift[0], atol=1e-6)
    for b in ("scaphoid", "lunate", "triquetrum"):
        shift = parts[b].vertices - raw[b].vertices
        assert np.allclose(shift, shift[0], atol=1e-6)


@pytest.mark.slow
def test_the_shipped_seat_is_the_fit():
    fitted = midcarpal.seat_distal_row(oriented_parts()[0], JOINT_SPACE_MM)
    assert np.allclose(fitted, midcarpal.read_seat(), atol=1e-6)
