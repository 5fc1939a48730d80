"""The distal row's rigidity measures (`validation.measures`): the radial column's and the hamate's turn
from the capitate over a run's poses; fast, on hand-made poses."""

import numpy as np
from scipy.spatial.transform import Rotation

from wrist_env.model import CAPITATE, HAMATE, N_BODIES, TRAPEZIUM
from wrist_env.validation import SOURCES, largest_rotation_deg


def _poses(n_frames: int) -> np.ndarray:
    return np.tile(np.eye(4), (n_frames, N_BODIES, 1, 1))


def test_the_hamates_turn_is_measured_from_the_capitate_not_from_neutral():
    """The capitate and the hamate flexed together through ±40 deg read 0 deg; the hamate turned a further
    2.5 deg (any axis) on one frame reads 2.5 deg; the column's measure does not see it (nor the hamate the
    column's), and translations do not count."""
    poses = _poses(5)
    for f, angle in enumerate(np.linspace(-40.0, 40.0, 5)):
        flex = Rotation.from_rotvec([0.0, 0.0, np.radians(angle)]).as_matrix()
        for b in (CAPITATE, HAMATE, TRAPEZIUM):
            poses[f, b, :3, :3] = flex
            poses[f, b, :3, 3] = (0.5 * f, -0.2, 1.0)
    assert largest_rotation_deg(poses, HAMATE) < 1e-4 and largest_rotation_deg(poses, TRAPEZIUM) < 1e-4
    extra = Rotation.from_rotvec(np.radians(2.5) * np.array([0.6, 0.0, 0.8])).as_matrix()
    poses[3, HAMATE, :3, :3] = extra @ poses[3, CAPITATE, :3, :3]
    assert np.isclose(largest_rotation_deg(poses, HAMATE), 2.5) and largest_rotation_deg(poses, TRAPEZIUM) < 1e-4
    poses[1, TRAPEZIUM, :3, :3] = extra @ poses[1, CAPITATE, :3, :3]
    assert np.isclose(largest_rotation_deg(poses, TRAPEZIUM), 2.5) and np.isclose(
        largest_rotation_deg(poses, HAMATE), 2.5
    )


def test_the_hamates_check_cites_the_distal_rows_rigidity():
    assert "Akhbari" in SOURCES["hamate_rotation_deg"] and "Ritt" in SOURCES["hamate_rotation_deg"]
