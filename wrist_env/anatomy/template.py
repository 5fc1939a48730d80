"""The anatomy template: myo-sim bones in the radius coordinate system (RCS).

RCS (modified ISB, right wrist): origin at the centre of the distal radius
articular surface, x volar, y proximal (along the shaft), z radial. It is
defined from landmarks, not assumed from the mesh frame:

- y: principal axis of the radius shaft, pointing away from the carpus;
- x: from the extensor to the flexor tendons crossing the wrist (MJCF sites),
  made orthogonal to y;
- z = x × y (radial for a right wrist; tests check the radial styloid and
  the scaphoid lie radial);
- origin: centre of the rebuilt articular surface (scaphoid + lunate fossae).

Bones: the carpal meshes as shipped (watertight, ~0.7 mm edges); the radius
is the rebuilt articular solid (0.4 mm grid) plus the distal 20 mm of the
shaft subdivided to ≤ 1.5 mm (for ligament sites and display); the ulna is its
distal 20 mm subdivided likewise.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import ArrayLike

from wrist_env.anatomy.midcarpal import DISTAL_ROW, read_seat
from wrist_env.anatomy.myosim import load_myosim_anatomy
from wrist_env.anatomy.radius_cap import build_radius_cap
from wrist_env.anatomy.ulnar_variance import ulnar_corner
from wrist_env.limits import check_fossa_sweep
from wrist_env.model import BODY_PARTS, BONES, CARPALS, CARRIED_WITH, OPTIONAL_BONES, PARTS, SUPPLIED

ROW = ("scaphoid", "lunate")  # the proximal row bones that articulate with the radius
JOINT_SPACE_MM = 1.5  # radiocarpal bone-to-bone joint space of the rebuilt fossae
SHAFT_LENGTH_MM = 20.0
SHAFT_EDGE_MM = 1.5


def vertex_areas(vertices: ArrayLike, faces: ArrayLike) -> np.ndarray:
    """Area (n,) mm² owned by each vertex: a third of each face it is a corner of (they sum to the mesh's)."""
    v, f = np.asarray(vertices, dtype=np.float64), np.asarray(faces)
    out = np.zeros(len(v))
    np.add.at(out, f.ravel(), np.repeat(trimesh.triangles.area(v[f]) / 3.0, 3))
    return out


@dataclass(frozen=True)
class BoneSurface:
    """One rigid bone surface in the RCS.

    vertices: array of shape (n, 3), mm. faces: array of shape (m, 3), int64.
    solid: bool array of shape (n,): vertices of the watertight part that
        carries contact and mass (all True for carpal bones; the rebuilt
        articular solid for the radius; none for the ulna).
    part: int array of shape (n,): index into `BODY_PARTS[name]` of the bone of each
        vertex (all 0 for a single bone; see `compose`).
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    solid: np.ndarray
    part: np.ndarray | None = None

    def __post_init__(self):
        if self.part is None:
            object.__setattr__(self, "part", np.zeros(len(self.vertices), np.int64))

    def trimesh(self, solid_only: bool = False) -> trimesh.Trimesh:
        """The surface as a trimesh (optionally only its watertight part)."""
        faces = self.faces
        if solid_only:
            faces = faces[self.solid[faces].all(axis=1)]
        mesh = trimesh.Trimesh(self.vertices, faces, process=False)
        if solid_only:
            mesh.remove_unreferenced_vertices()
        return mesh


@dataclass(frozen=True)
class Template:
    """The template in the RCS (mm), neutral pose.

    bones: the rigid bodies (`BONES`); with the distal row, each composed of its
        `BODY_PARTS`, otherwise the principal bones alone (and the radial column).
    parts: the nine bones one by one (`PARTS`).
    rcs_from_myosim: 4x4 transform from the myo-sim radius body frame (mm) to the RCS (the distal
        row's bones are moved on from there by `midcarpal.read_seat()`).
    """

    bones: dict
    parts: dict
    rcs_from_myosim: np.ndarray


def compose(parts: dict, distal_row: bool = True) -> dict:
    """The rigid bodies from the bones (name -> BoneSurface): each body's parts concatenated in
    `BODY_PARTS` order, with `part` labels (without the distal row: the principal bones alone, and the
    radial column, a body of its own, whole)."""
    bodies = {}
    for body in BONES:
        whole = distal_row or body not in SUPPLIED
        members = [parts[p] for p in (BODY_PARTS[body] if whole else BODY_PARTS[body][:1])]
        counts = np.cumsum([0] + [len(m.vertices) for m in members])
        bodies[body] = BoneSurface(
            body,
            np.vstack([m.vertices for m in members]),
            np.vstack([m.faces + c for m, c in zip(members, counts)]).astype(np.int64),
            np.concatenate([m.solid for m in members]),
            np.concatenate([np.full(len(m.vertices), k, np.int64) for k, m in enumerate(members)]),
        )
    return bodies


def _registration(source: "BoneSurface", target: "BoneSurface") -> np.ndarray:
    """The similarity (4×4: rotation, translation, isotropic scale) that registers `source` onto
    `target` (ICP from the shared RCS)."""
    mesh = trimesh.Trimesh(target.vertices, target.faces, process=False)
    T, _, _ = trimesh.registration.icp(
        source.vertices, mesh, initial=np.eye(4), threshold=1e-6, max_iterations=60, reflection=False, scale=True
    )
    return T


def carry_parts(bodies: dict, template: "Template", distal_row: bool = True, given: dict | None = None) -> dict:
    """All bodies for a participant who supplies the principal bones (`SUPPLIED`: name -> BoneSurface, RCS
    mm) and perhaps some others (`given`: part name in `OPTIONAL_BONES` -> BoneSurface): each other bone of
    a supplied body (`BODY_PARTS`; with `distal_row`) and each carried body (`CARRIED_WITH`) is the given
    one, or else the template's, carried by the similarity that registers the template's principal bone of
    its supplied body onto the participant's."""
    given = given or {}
    unknown = sorted(set(given) - set(OPTIONAL_BONES))
    if unknown:
        raise ValueError(f"given bones must be among {OPTIONAL_BONES}, but got {unknown}")
    parts = {b: bodies[b] for b in SUPPLIED}
    moved = {}
    for body in SUPPLIED:
        extra = list(BODY_PARTS[body][1:]) if distal_row else []
        extra += [p for c, host in CARRIED_WITH.items() if host == body for p in BODY_PARTS[c]]
        moved |= {p: given[p] for p in extra if p in given}
        carried = [p for p in extra if p not in given]
        if not carried:
            continue
        T = _registration(template.parts[body], bodies[body])
        for p in carried:
            src = template.parts[p]
            moved[p] = BoneSurface(p, src.vertices @ T[:3, :3].T + T[:3, 3], src.faces.copy(), src.solid.copy())
    return compose(parts | moved, distal_row)


def rcs_rotation(
    radius: trimesh.Trimesh, carpus_centroid: ArrayLike, flexor_sites: np.ndarray, extensor_sites: np.ndarray
) -> np.ndarray:
    """Rows x (volar), y (proximal), z (radial) of the RCS in the myo-sim frame."""
    centred = radius.vertices - radius.vertices.mean(axis=0)
    y = np.linalg.svd(centred, full_matrices=False)[2][0]
    if np.dot(radius.vertices.mean(axis=0) - carpus_centroid, y) < 0:
        y = -y
    volar = flexor_sites.mean(axis=0) - extensor_sites.mean(axis=0)
    x = volar - np.dot(volar, y) * y
    x /= np.linalg.norm(x)
    z = np.cross(x, y)
    return np.vstack([x, y, z])


def _distal_part(mesh: trimesh.Trimesh, y_max: float) -> trimesh.Trimesh:
    """Faces of `mesh` with any vertex below `y_max`, subdivided to ≤ SHAFT_EDGE_MM."""
    keep = (mesh.vertices[mesh.faces][:, :, 1] < y_max).any(axis=1)
    verts, faces = trimesh.remesh.subdivide_to_size(mesh.vertices, mesh.faces[keep], max_edge=SHAFT_EDGE_MM)
    part = trimesh.Trimesh(verts, faces, process=True)
    part.remove_unreferenced_vertices()
    return part


def closed(surface: BoneSurface) -> BoneSurface:
    """The bone with each open boundary loop (a cut shaft) closed by a fan to the loop's centroid,
    all of it solid: the ulna's head for its contact grid (the TFCC, `model.PAIRS` "ulnocarpal").
    A closed bone comes back as it is."""
    faces = np.asarray(surface.faces, dtype=np.int64)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    _, inverse, counts = np.unique(np.sort(edges, axis=1), axis=0, return_inverse=True, return_counts=True)
    boundary = edges[counts[inverse.ravel()] == 1]
    if len(boundary) == 0:
        return surface
    after = dict(zip(boundary[:, 1].tolist(), boundary[:, 0].tolist()))  # each loop against the faces' order
    centres, fans, parts = [], [], []
    while after:
        loop = [next(iter(after))]
        while after[loop[-1]] != loop[0]:
            loop.append(after.pop(loop[-1]))
        after.pop(loop[-1])
        centre = len(surface.vertices) + len(centres)
        centres.append(surface.vertices[loop].mean(axis=0))
        parts.append(surface.part[loop[0]])
        fans.extend([loop[k], loop[(k + 1) % len(loop)], centre] for k in range(len(loop)))
    vertices = np.vstack([surface.vertices, centres])
    return BoneSurface(
        surface.name,
        vertices,
        np.vstack([faces, np.asarray(fans, dtype=np.int64)]),
        np.ones(len(vertices), bool),
        np.concatenate([surface.part, parts]).astype(np.int64),
    )


def _transform(mesh: trimesh.Trimesh, T: np.ndarray) -> trimesh.Trimesh:
    out = mesh.copy()
    out.apply_transform(T)
    return out


def oriented_parts() -> tuple[dict, np.ndarray]:
    """The nine myo-sim bones as myo-sim assembles them, turned to the RCS axes (not yet centred):
    part name -> trimesh (mm), and that rotation (4×4)."""
    anatomy = load_myosim_anatomy()
    meshes = anatomy.meshes
    carpus = np.mean([meshes[b].centroid for b in CARPALS], axis=0)
    oriented = np.eye(4)
    oriented[:3, :3] = rcs_rotation(meshes["radius"], carpus, anatomy.flexor_sites, anatomy.extensor_sites)
    return {b: _transform(meshes[b], oriented) for b in PARTS}, oriented


@functools.lru_cache(maxsize=4)
def load_template(fossa_sweep_deg: tuple = (0.0, 0.0), distal_row: bool = False) -> Template:
    """The anatomy template (built once per process and variant, ~1–5 s).

    fossa_sweep_deg: (flexion, deviation) half-ranges (deg) of the row's sweep that shapes
    the radius fossae ((0, 0): moulded to the neutral row). distal_row: the lunate body
    carries the triquetrum and the capitate body the trapezium, trapezoid and hamate.
    """
    fossa_sweep_deg = check_fossa_sweep(fossa_sweep_deg)  # NaN or out-of-range angles: refused, not swept
    m, oriented = oriented_parts()
    seat = read_seat()
    m |= {b: _transform(m[b], seat) for b in DISTAL_ROW}
    cap, articular = build_radius_cap([m[b] for b in ROW], m["radius"], joint_space_mm=JOINT_SPACE_MM)
    top = cap.vertices[articular]  # the origin comes from the moulded envelope, whatever the variant
    origin = top[np.argmin(np.linalg.norm(top[:, [0, 2]] - top[:, [0, 2]].mean(axis=0), axis=1))]
    to_rcs = np.eye(4)
    to_rcs[:3, 3] = -origin
    # The fossae end at myo-sim's radius' ulnar border (issue 54): unbounded, the row's envelope ran on
    # ulnar over the ulnocarpal space (docs/history.md, issue 54 step 1). The origin stays the unbounded
    # envelope's: the RCS the annotations are placed in.
    border_z = ulnar_corner(m["radius"].vertices - origin)[2] + origin[2]
    cap, _ = build_radius_cap(
        [m[b] for b in ROW],
        m["radius"],
        joint_space_mm=JOINT_SPACE_MM,
        sweep_deg=tuple(float(a) for a in fossa_sweep_deg),
        ulnar_border_z=border_z,
    )
    rcs_from_myosim = to_rcs @ oriented
    m = {b: _transform(mesh, to_rcs) for b, mesh in m.items()}
    cap = _transform(cap, to_rcs)

    y_cut = SHAFT_LENGTH_MM
    shaft = _distal_part(m["radius"], y_cut)
    radius_vertices = np.vstack([cap.vertices, shaft.vertices])
    radius_faces = np.vstack([cap.faces, shaft.faces + len(cap.vertices)])
    radius_solid = np.arange(len(radius_vertices)) < len(cap.vertices)
    ulna = _distal_part(m["ulna"], y_cut)
    bones = {
        "radius": BoneSurface("radius", radius_vertices, radius_faces.astype(np.int64), radius_solid),
        "ulna": closed(
            BoneSurface("ulna", ulna.vertices.copy(), ulna.faces.astype(np.int64), np.zeros(len(ulna.vertices), bool))
        ),
    }
    for b in PARTS[2:]:
        bones[b] = BoneSurface(b, m[b].vertices.copy(), m[b].faces.astype(np.int64), np.ones(len(m[b].vertices), bool))
    bodies = compose(bones, distal_row)
    for bone in list(bones.values()) + list(bodies.values()):
        for arr in (bone.vertices, bone.faces, bone.solid, bone.part):
            arr.setflags(write=False)
    rcs_from_myosim.setflags(write=False)
    return Template(bones=bodies, parts=bones, rcs_from_myosim=rcs_from_myosim)
