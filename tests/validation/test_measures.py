"""The rigidity measures (`validation.measures`): the radial column's and the hamate's turn from the capitate,
the triquetrum's from the lunate, over a run's poses; fast, on hand-made poses."""

import numpy as np
from scipy.spatial.transform import Rotation

from wrist_env.model import CAPITATE, HAMATE, LUNATE, N_BODIES, TRAPEZIUM, TRIQUETRUM
from wrist_env.validation import (
    LUNOTRIQUETRAL_DEG,
    SOURCES,
    column_rotation_deg,
    hamate_rotation_deg,
    lunotriquetral_rotation_deg,
)


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
    assert hamate_rotation_deg(poses) < 1e-4 and column_rotation_deg(poses) < 1e-4
    extra = Rotation.from_rotvec(np.radians(2.5) * np.array([0.6, 0.0, 0.8])).as_matrix()
    poses[3, HAMATE, :3, :3] = extra @ poses[3, CAPITATE, :3, :3]
    assert np.isclose(hamate_rotation_deg(poses), 2.5) and column_rotation_deg(poses) < 1e-4
    poses[1, TRAPEZIUM, :3, :3] = extra @ poses[1, CAPITATE, :3, :3]
    assert np.isclose(column_rotation_deg(poses), 2.5) and np.isclose(hamate_rotation_deg(poses), 2.5)


def test_the_hamates_check_cites_the_distal_rows_rigidity():
    assert "Akhbari" in SOURCES["hamate_rotation_deg"] and "Ritt" in SOURCES["hamate_rotation_deg"]


def test_the_lunotriquetral_turn_is_measured_from_the_lunate_not_from_the_capitate():
    """The lunate and the triquetrum flexed together through ±20 deg (the capitate ±40) read 0 deg; the
    triquetrum turned a further 3 deg on one frame reads 3 deg; the capitate's own turn does not count."""
    poses = _poses(5)
    for f, angle in enumerate(np.linspace(-40.0, 40.0, 5)):
        for b, share in ((CAPITATE, 1.0), (LUNATE, 0.5), (TRIQUETRUM, 0.5)):
            poses[f, b, :3, :3] = Rotation.from_rotvec([0.0, 0.0, np.radians(share * angle)]).as_matrix()
            poses[f, b, :3, 3] = (0.3 * f, 0.1, -0.5)
    assert lunotriquetral_rotation_deg(poses) < 1e-4
    extra = Rotation.from_rotvec(np.radians(3.0) * np.array([0.0, 0.6, 0.8])).as_matrix()
    poses[2, TRIQUETRUM, :3, :3] = extra @ poses[2, LUNATE, :3, :3]
    assert np.isclose(lunotriquetral_rotation_deg(poses), 3.0) and hamate_rotation_deg(poses) > 10.0


def test_the_lunotriquetral_check_cites_the_proximal_rows_kinematics():
    assert "Ruby" in SOURCES["lunotriquetral_rotation_deg"] and "Kobayashi" in SOURCES["lunotriquetral_rotation_deg"]
    assert 0.0 < LUNOTRIQUETRAL_DEG <= 10.0
