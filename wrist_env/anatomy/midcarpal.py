"""Seat the distal row on the proximal row at one midcarpal joint space.

myo-sim assembles its carpal bones for a musculoskeletal model, not for
contact: bone to bone, its capitolunate and triquetrohamate facets are
0.5–0.6 mm apart and its scaphotrapezial facet 2.4 mm. Normal carpal joint
spaces are parallel and of one width (Gilula 1979, AJR 133:503, "parallelism":
~2 mm on radiographs), and the distal row moves as one unit (Akhbari 2019).
So the template's distal row is moved rigidly to the pose that brings the
closest approaches of its five midcarpal facets nearest, in least squares,
to the joint space the radius fossae are rebuilt at (`template.JOINT_SPACE_MM`).
The fit is authored data (`data/distal_row_seat.json`, written by
`python experiments/authoring/make_annotations.py`), read by the template.
"""

from __future__ import annotations

import importlib.resources
import json

import igl
import numpy as np
from scipy.optimize import minimize
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

FACETS = (
    ("scaphoid", "capitate"),
    ("scaphoid", "trapezium"),  # the STT joint
    ("scaphoid", "trapezoid"),
    ("lunate", "capitate"),
    ("triquetrum", "hamate"),  # the helicoid triquetrohamate joint
)
"""The midcarpal facets: (proximal row bone, distal row bone)."""
DISTAL_ROW = ("capitate", "trapezium", "trapezoid", "hamate")
"""The four distal row bones, seated as one (the capitate body and the radial column)."""
FACET_REACH_MM = 2.0  # proximal-row vertices within this of a facet's closest approach stand for it
SMALLEST_MOVE = 1e-3  # weight of the move (deg², mm²) in the least squares: the smallest move of several equal fits


def _pose(x: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """4×4 rigid transform: rotation vector x[:3] (deg) about `centre` (mm), then translation x[3:] (mm)."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(np.radians(x[:3])).as_matrix()
    T[:3, 3] = centre - T[:3, :3] @ centre + x[3:]
    return T


def _facets(meshes: dict) -> list[tuple]:
    """Per facet: the proximal points near it, and the distal bone's faces near them (vertices, faces)."""
    facets = []
    for proximal, distal in FACETS:
        v = np.asarray(meshes[proximal].vertices, dtype=np.float64)
        dv, df = np.asarray(meshes[distal].vertices, dtype=np.float64), np.asarray(meshes[distal].faces, np.int64)
        d = np.sqrt(igl.point_mesh_squared_distance(v, dv, df)[0])
        reach = d.min() + FACET_REACH_MM  # seating changes each facet's gap by < 1 mm: its closest point stays in
        points = v[d < reach]
        near = cKDTree(points).query(dv, distance_upper_bound=reach + FACET_REACH_MM)[0] < np.inf
        facets.append((points, dv, df[near[df].any(axis=1)]))
    return facets


def facet_gaps(meshes: dict, T: np.ndarray | None = None, facets: list | None = None) -> np.ndarray:
    """Closest approach (mm, shape (5,), `FACETS` order) of each facet, the distal row moved by T (4×4)."""
    T = np.eye(4) if T is None else T
    gaps = []
    for points, dv, df in _facets(meshes) if facets is None else facets:
        # moving the distal bone by T is moving the proximal points by T⁻¹
        q = (points - T[:3, 3]) @ T[:3, :3]
        gaps.append(np.sqrt(igl.point_mesh_squared_distance(q, dv, df)[0].min()))
    return np.array(gaps)


def seat_distal_row(meshes: dict, joint_space_mm: float, facets: list | None = None) -> np.ndarray:
    """The rigid transform (4×4, mm) of the distal row that seats it at `joint_space_mm` (see module).

    meshes: part name -> trimesh in one frame (mm), the proximal row and the distal row's bones;
    facets: their `_facets` if already found."""
    facets = _facets(meshes) if facets is None else facets
    centre = np.mean([meshes[b].centroid for b in DISTAL_ROW], axis=0)

    def misfit(x):
        gaps = facet_gaps(meshes, _pose(x, centre), facets)
        return float(np.sum((gaps - joint_space_mm) ** 2) + SMALLEST_MOVE * np.sum(x**2))

    best = minimize(misfit, np.zeros(6), method="Nelder-Mead", options={"maxiter": 4000, "xatol": 1e-2, "fatol": 1e-6})
    return _pose(best.x, centre)


SEAT_FILE = "distal_row_seat.json"


def read_seat() -> np.ndarray:
    """The distal row's seating transform (4×4, mm, in the RCS axes before centring) shipped with the package."""
    data = json.loads((importlib.resources.files("wrist_env.anatomy") / "data" / SEAT_FILE).read_text())
    return np.asarray(data["transform"], dtype=np.float64)


def seat_record(meshes: dict, joint_space_mm: float) -> dict:
    """The fit as plain data: the transform, its rotation (deg) and translation (mm), the facet gaps before and after."""
    facets = _facets(meshes)
    T = seat_distal_row(meshes, joint_space_mm, facets)
    return {
        "about": "the distal row's rigid seating at one midcarpal joint space (wrist_env.anatomy.midcarpal); "
        "written by experiments/authoring/make_annotations.py",
        "joint_space_mm": joint_space_mm,
        "facets": [list(f) for f in FACETS],
        "facet_gaps_before_mm": np.round(facet_gaps(meshes, None, facets), 3).tolist(),
        "facet_gaps_after_mm": np.round(facet_gaps(meshes, T, facets), 3).tolist(),
        "rotation_vector_deg": np.round(np.degrees(Rotation.from_matrix(T[:3, :3]).as_rotvec()), 3).tolist(),
        "transform": T.tolist(),
    }
