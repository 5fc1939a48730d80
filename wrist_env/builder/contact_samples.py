"""Contact samples of a model, pair-sorted, seated out of the opposing signed-distance grids.

Per sample: a point (mm) on its pair's sample bone's bone-plus-cartilage surface, ~1 mm apart
(`BuildParams.contact_spacing_mm`), its unit normal, its area (mm²) and the total cartilage thickness of
both layers there (mm; the TFCC's counted at its cartilage-equivalent thickness, `_compliant`).
"""

from __future__ import annotations

import numpy as np
import trimesh
from scipy.spatial import cKDTree

from wrist_env.anatomy.template import vertex_areas
from wrist_env.builder import sdf
from wrist_env.builder.surface import displaced_vertices
from wrist_env.errors import BuildError
from wrist_env.model import BONES, PAIR_BONES, PAIRS, offsets

SEAT_ITERATIONS = 6  # `_seat_samples`: the TFCC's domed layer needs more than the cartilage's 3


def _thin(points, spacing_mm) -> np.ndarray:
    """Indices of one point per `spacing_mm` voxel (the one nearest its voxel centre)."""
    cell = np.floor(points / spacing_mm).astype(np.int64)
    d = np.linalg.norm(points / spacing_mm - cell - 0.5, axis=1)
    order = np.lexsort((d, cell[:, 2], cell[:, 1], cell[:, 0]))
    c = cell[order]
    first = np.ones(len(order), bool)
    first[1:] = np.any(c[1:] != c[:-1], axis=1)
    return order[first], order, np.cumsum(first) - 1


def _compliant(bone: str, thickness: np.ndarray, params) -> np.ndarray:
    """A layer's thickness (mm) as the contact law counts it: the ulna's TFCC layer at its thickness over
    its stiffness relative to cartilage (`BuildParams.tfc_modulus_ratio`; layers in series: a layer k times
    softer strains like one k times thicker), cartilage as it is."""
    return thickness / params.tfc_modulus_ratio if bone == "ulna" else thickness


def _contact_samples(bones, thickness, coverage, params):
    """Pair-sorted contact samples on each pair's sample bone (see `Model`)."""
    pts, nrm, area, h, sizes = [], [], [], [], []
    paired = sorted({BONES[i] for i in np.unique(PAIR_BONES)})
    displaced = {b: displaced_vertices(bones[b].vertices, bones[b].faces, thickness[b]) for b in paired}
    for p, art in enumerate(PAIRS):
        a, b = BONES[PAIR_BONES[p][0]], BONES[PAIR_BONES[p][1]]
        if art not in coverage:  # an articulation this variant lacks (`pipeline.ABSENT_WITHOUT_DISTAL_ROW`)
            sizes.append(0)
            continue
        ca, cb = coverage[art][2], coverage[art][3]
        if coverage[art][0] != a:
            ca, cb = cb, ca
        idx = np.flatnonzero(ca)
        if len(idx) == 0:
            raise BuildError(f"articulation {art} has no cartilage coverage on the {a}")
        mesh = trimesh.Trimesh(displaced[a], bones[a].faces, process=False)
        vertex_area = vertex_areas(displaced[a], bones[a].faces)[idx]
        keep, order, group = _thin(displaced[a][idx], params.contact_spacing_mm)
        sample_area = np.bincount(group, weights=vertex_area[order])
        chosen = idx[keep]
        partner = np.flatnonzero(cb)
        _, nearest = cKDTree(displaced[b][partner]).query(displaced[a][chosen])
        total = _compliant(a, thickness[a][chosen], params) + _compliant(b, thickness[b][partner[nearest]], params)
        pts.append(displaced[a][chosen])
        nrm.append(mesh.vertex_normals[chosen])
        area.append(sample_area)
        h.append(np.maximum(total, params.min_total_thickness_mm))
        sizes.append(len(chosen))
    return displaced, np.vstack(pts), np.vstack(nrm), np.concatenate(area), np.concatenate(h), offsets(sizes)


def _seat_samples(points, normals, sample_offsets, grids):
    """Remove what overclosure the grids still see in the neutral pose (interpolation of
    curved surfaces): each sample inside the opposing grid moves back along its normal.

    Returns the points and the largest correction (mm).
    """
    points = points.copy()
    worst = 0.0
    for p in range(len(PAIRS)):
        grid = grids[BONES[PAIR_BONES[p][1]]]
        sl = slice(sample_offsets[p], sample_offsets[p + 1])
        if sample_offsets[p + 1] == sample_offsets[p]:  # a pair without samples (`pipeline.ABSENT_WITHOUT_DISTAL_ROW`)
            continue
        for _ in range(SEAT_ITERATIONS):
            d, _ = sdf.trilinear(grid, points[sl])
            inside = np.minimum(d, 0.0)
            worst = max(worst, float(-inside.min()))
            points[sl] += inside[:, None] * normals[sl]
    return points, worst
