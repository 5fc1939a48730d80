"""Template annotations: cartilage coverage and ligament attachment sites.

The data file `data/annotations.json` (authored by
`experiments/authoring/make_annotations.py`, reviewed in a figure) gives, in the
template RCS (mm): for each articulation its two bones and the largest
bone-to-bone gap that cartilage covers; for each Table 2 ligament the bone,
centre and radius of its origin and insertion sites. This module resolves
them to vertex masks on the template bones.
"""

from __future__ import annotations

import functools
import importlib.resources
import json
from dataclasses import dataclass

import igl
import numpy as np
from numpy.typing import ArrayLike

from wrist_env.anatomy.template import load_template
from wrist_env.ligaments import ALL_LIGAMENT_NAMES, LIGAMENT_NAMES
from wrist_env.model import BODY_PARTS, PAIRS


@dataclass(frozen=True)
class Site:
    """A ligament attachment site: bone name and vertex mask of shape (n_vertices,)."""

    bone: str
    mask: np.ndarray


@dataclass(frozen=True)
class Annotations:
    """Resolved annotations on one set of bones.

    coverage: articulation -> (bone_a, bone_b, mask_a, mask_b), masks over vertices.
    sites: ligament -> (origin Site, insertion Site).
    """

    coverage: dict
    sites: dict


def read_annotation_data() -> dict:
    """The raw annotation data (JSON) shipped with the package."""
    path = importlib.resources.files("wrist_env.anatomy") / "data" / "annotations.json"
    return json.loads(path.read_text())


def facing_within(
    vertices: ArrayLike,
    normals: ArrayLike,
    partner_vertices: np.ndarray,
    partner_faces: np.ndarray,
    max_gap_mm: float,
) -> np.ndarray:
    """Bool mask: vertices within `max_gap_mm` of the partner surface whose normal faces it."""
    d2, _, closest = igl.point_mesh_squared_distance(
        np.ascontiguousarray(vertices, dtype=np.float64), partner_vertices, partner_faces
    )
    towards = np.einsum("ij,ij->i", normals, closest - vertices)
    return (np.sqrt(d2) < max_gap_mm) & (towards > 0)


ENDS = ("origin", "insertion")


def _has_part(bones: dict, spec: dict) -> bool:
    """Whether the body of a site spec carries the bone (`part`) the site lies on."""
    return "part" not in spec or BODY_PARTS[spec["bone"]].index(spec["part"]) <= bones[spec["bone"]].part.max()


def resolve(bones: dict, data: dict | None = None) -> Annotations:
    """Resolve annotation data on `bones` (name -> BoneSurface in the template RCS).

    A site lies on one bone of its body (its `part`, default the principal bone; e.g. the
    DRC's insertion on the triquetrum); on bodies without that part (no distal row) its
    `without_part` site is used instead, and a fixed ligament (`ligaments.FIXED_LIGAMENTS`)
    without one is not built.
    """
    data = read_annotation_data() if data is None else data
    solids = {name: b.trimesh(solid_only=True) for name, b in bones.items() if b.solid.any()}
    coverage = {}
    for art in PAIRS:  # each contact pair's cartilage (`model.PAIRS`)
        spec = data["cartilage"][art]
        a, b = spec["bones"]
        masks = []
        for me, other in ((a, b), (b, a)):
            surface = bones[me].trimesh()
            mask = facing_within(
                surface.vertices,
                surface.vertex_normals,
                solids[other].vertices,
                solids[other].faces.astype(np.int64),
                spec["max_gap_mm"],
            )
            masks.append(mask & bones[me].solid)
        coverage[art] = (a, b, masks[0], masks[1])
    sites = {}
    for lig in ALL_LIGAMENT_NAMES:
        if lig not in LIGAMENT_NAMES and not all(_has_part(bones, data["ligaments"][lig][end]) for end in ENDS):
            continue  # a fixed ligament of a bone this variant lacks (the distal row's)
        pair = []
        for end in ENDS:
            spec = data["ligaments"][lig][end]
            if not _has_part(bones, spec):
                spec = spec["without_part"]
            body = bones[spec["bone"]]
            own = body.part == BODY_PARTS[spec["bone"]].index(spec.get("part", spec["bone"]))
            distance = np.where(own, np.linalg.norm(body.vertices - np.asarray(spec["centre_mm"]), axis=1), np.inf)
            # a site off this variant's surface (a swept fossa's rim) moves to the nearest surface point
            if distance.min() > 0.5 * spec["radius_mm"]:
                nearest = body.vertices[np.argmin(distance)]
                distance = np.where(own, np.linalg.norm(body.vertices - nearest, axis=1), np.inf)
            mask = distance <= spec["radius_mm"]
            pair.append(Site(spec["bone"], mask))
        sites[lig] = tuple(pair)
    return Annotations(coverage=coverage, sites=sites)


@functools.lru_cache(maxsize=4)
def template_annotations(fossa_sweep_deg: tuple = (0.0, 0.0), distal_row: bool = False) -> Annotations:
    """Annotations resolved on the anatomy template (variant as in `load_template`)."""
    return resolve(load_template(tuple(fossa_sweep_deg), distal_row).bones)
