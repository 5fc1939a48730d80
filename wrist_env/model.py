"""The simulation-ready participant model: immutable arrays, saved as `.npz` + JSON.

All positions are in the RCS at the neutral pose (mm), which is also each
bone's own frame: a bone's pose is the 4x4 transform of its neutral-pose
points. Ragged per-bone or per-pair data are concatenated with offsets, so
`x[offsets[i]:offsets[i + 1]]` is item i; this is the layout the kernels read.

Shapes in the package's docstrings are written in these symbols, not in the current counts, which
change as the model grows:

- n_bodies: the rigid bodies, `N_BODIES = len(BONES)`; n_bones in the solver is the same count.
- n_free: the bodies free in 6 DOF, `len(FREE)`.
- n_pairs: the contact pairs, `len(PAIRS)`; n_samples: the contact samples of all pairs.
- n_bundles: the ligament bundles the solver pulls, `len(ligaments.ALL_LIGAMENT_NAMES)` (the design's
  ligaments, then the fixed ones); n_ligaments in a design: `design.N_LIGAMENTS`, the 11 of Table 2.
- n_frames: the frames of a driver or trial; n_nodes: the RSC membrane's nodes.

What is fixed stays a number: 27 design variables, 22 materials, 2 bones × 6 DOF = 12 errors, 4×4
transforms, 3 axes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from wrist_env.errors import InputError
from wrist_env.io import load_dataclass, save_dataclass

__all__ = [
    "BONES",
    "RADIUS",
    "ULNA",
    "SCAPHOID",
    "LUNATE",
    "CAPITATE",
    "TRAPEZIUM",
    "HAMATE",
    "N_BODIES",
    "FREE",
    "CARRIED",
    "BODY_PARTS",
    "SUPPLIED",
    "OPTIONAL_BONES",
    "CARPALS",
    "CARRIED_WITH",
    "PARTS",
    "PAIRS",
    "PAIR_BONES",
    "ARTICULATIONS",
    "MIDCARPAL",
    "Model",
    "offsets",
]

BONES = ("radius", "ulna", "scaphoid", "lunate", "capitate", "trapezium", "hamate")
"""The seven rigid bodies, each named after its principal bone."""
RADIUS, ULNA, SCAPHOID, LUNATE, CAPITATE, TRAPEZIUM, HAMATE = range(7)
N_BODIES = len(BONES)
FREE = (SCAPHOID, LUNATE, TRAPEZIUM, HAMATE)
"""The bodies free in 6 DOF under every driver (the capitate is driven; the radius and ulna fixed)."""
CARRIED = (TRAPEZIUM, HAMATE)
"""The free bodies of the distal row, which the driven capitate carries: their dislocation is measured
from where the capitate carries them (`solver.stopping.displacement`)."""
BODY_PARTS = {
    "radius": ("radius",),
    "ulna": ("ulna",),
    "scaphoid": ("scaphoid",),
    "lunate": ("lunate", "triquetrum"),
    "capitate": ("capitate",),
    "trapezium": ("trapezium", "trapezoid"),
    "hamate": ("hamate",),
}
"""The bones of each rigid body, principal bone first: the triquetrum moves with the lunate
(lunotriquetral motion is small beside scapholunate motion: Ruby 1988, Kobayashi 1997). The trapezium
and trapezoid are the radial column, a body of its own: it loads the scaphoid's distal pole through the
STT joint with the 1st and 2nd rays' loads (issue 33: with it on the driven capitate no load reached the
STT joint), held to the capitate by the trapezocapitate ligaments and joint (`ligaments.FIXED_LIGAMENTS`).
The hamate is a body of its own too (issue 54, step 2), as in every full-carpus model that bears load
(Fischli 2009, J Biomech 42:1363; Bajuri 2012, Proc IMechE H): on the driven capitate, the moment of
its rays' loads (the 4th and 5th metacarpals and, through the pisiform, the FCU: 38 % of the tendon
rig's tension) went to the driver and the capitate head took their load; free, it balances them on
its own joints (capitohamate, triquetrohamate), held to the capitate by the three capitohamate
interosseous ligaments of measured constraint (Ritt, Berger, Bishop & An 1996, J Hand Surg Br
21:451; `ligaments.HAMATE_LIGAMENTS`). The capitohamate joint still moves little (the distal row moves
rigidly together, < 3 deg: Akhbari 2019, J Orthop Res 37:2661; `validation` checks it)."""
SUPPLIED = ("radius", "ulna", "scaphoid", "lunate", "capitate")
"""The bodies a participant folder supplies meshes of (the principal bones); the radial column, the
hamate and the other parts are carried from the template with the capitate (`anatomy.template.carry_parts`)
unless the folder gives them too (`OPTIONAL_BONES`)."""
OPTIONAL_BONES = ("triquetrum", "trapezium", "trapezoid", "hamate")
"""The bones a participant folder may give besides `SUPPLIED` (a CT segmentation has them): each one given
is used as it is, each one not given is carried from the template (`anatomy.template.carry_parts`)."""
CARPALS = ("scaphoid", "lunate", "capitate")
"""The carpals a participant supplies meshes of and a trial tracks (the forearm bones are the radius and ulna)."""
CARRIED_WITH = {"trapezium": "capitate", "hamate": "capitate"}
"""Bodies not in `SUPPLIED`, and the supplied body whose registration carries them."""
PARTS = tuple(p for b in BONES for p in BODY_PARTS[b])
"""All nine bones of the model, body by body (`BODY_PARTS`)."""
PAIRS = (
    "radioscaphoid",
    "radiolunate",
    "scapholunate",
    "scaphocapitate",
    "lunocapitate",
    "scaphotrapezial",
    "trapeziocapitate",
    "ulnocarpal",
    "capitohamate",
    "triquetrohamate",
)
PAIR_BONES = np.array(
    [
        [SCAPHOID, RADIUS],
        [LUNATE, RADIUS],
        [SCAPHOID, LUNATE],
        [CAPITATE, SCAPHOID],
        [CAPITATE, LUNATE],
        [TRAPEZIUM, SCAPHOID],
        [TRAPEZIUM, CAPITATE],
        [LUNATE, ULNA],
        [HAMATE, CAPITATE],
        [LUNATE, HAMATE],
    ]
)
"""(sample bone, grid bone) of each contact pair: samples of the first are looked up in the second's grid.
"scaphotrapezial" is the STT joint (the trapezium's and trapezoid's facets on the scaphoid's distal
pole), "trapeziocapitate" the radial column against the capitate (chiefly the trapezoid–capitate joint),
"ulnocarpal" the lunate and triquetrum on the ulnar head through the TFCC, a compliant layer on the ulna
filling the ulnocarpal space (`builder.pipeline`): the ulnar load path (Palmer & Werner 1984).
"capitohamate" is the hamate against the capitate, "triquetrohamate" the lunate body (the triquetrum,
and the lunate where it reaches the hamate: a type II lunate's hamate facet, Viegas 1990) on the hamate."""
ARTICULATIONS = {
    "radioscaphoid": ("radioscaphoid", ("scaphoid",)),
    "radiolunate": ("radiolunate", ("lunate", "triquetrum")),
    "scapholunate": ("scapholunate", ("scaphoid",)),
    "scaphotrapeziotrapezoid": ("scaphotrapezial", ("trapezium", "trapezoid")),
    "scaphocapitate": ("scaphocapitate", ("capitate",)),
    "lunocapitate": ("lunocapitate", ("capitate",)),
    "triquetrohamate": ("triquetrohamate", ("triquetrum",)),
    "lunohamate": ("triquetrohamate", ("lunate",)),
    "trapeziocapitate": ("trapeziocapitate", ("trapezium", "trapezoid")),
    "ulnolunate": ("ulnocarpal", ("lunate",)),
    "ulnotriquetral": ("ulnocarpal", ("triquetrum",)),
    "capitohamate": ("capitohamate", ("hamate",)),
}
"""Each articulation as (contact pair, the parts of the pair's sample body on its side): a pair whose
sample body holds several bones (`BODY_PARTS`) spans several joints (the lunate body's samples on the
hamate are the triquetrohamate joint on the triquetrum, the lunohamate on the lunate)."""
MIDCARPAL = ("scaphotrapeziotrapezoid", "scaphocapitate", "lunocapitate", "triquetrohamate")
"""The midcarpal articulations whose load shares Viegas 1993 measured (STT, SC, LC, TH)."""


@dataclass(frozen=True)
class Model:
    """A participant model.

    Per-body arrays are in `BONES` order; ragged ones are concatenated, item i at
    `x[offsets[i]:offsets[i + 1]]`. Contact grids: one per bone; empty for the radial column; the ulna's
    its head, closed, with the TFCC. Contact samples: pair-sorted, n_pairs in `PAIRS` order, bones in
    `PAIR_BONES`. Ligament fibres: 1D bundles, Table 2 order.

    Parameters
    ----------
    name : str
        The participant's name.
    source_hash : str
        The hash of the inputs the model was built from (its cache key).
    vertices : np.ndarray, shape (n_vertices, 3)
        Every body's vertices, mm.
    vertex_offsets : np.ndarray, shape (n_bodies + 1,)
        The offsets of each body's vertices.
    faces : np.ndarray, shape (n_faces, 3)
        Triangles, indices local to their body.
    face_offsets : np.ndarray, shape (n_bodies + 1,)
        The offsets of each body's faces.
    vertex_part : np.ndarray, shape (n_vertices,)
        Index into `BODY_PARTS[body]` of the bone each vertex belongs to.
    thickness : np.ndarray, shape (n_vertices,)
        Cartilage thickness per vertex, mm (0 off cartilage).
    mass : np.ndarray, shape (n_bodies,)
        Each body's mass, t.
    com : np.ndarray, shape (n_bodies, 3)
        Each body's centre of mass, mm.
    inertia : np.ndarray, shape (n_bodies, 3, 3)
        Each body's inertia, t·mm², about the com, RCS axes.
    centroid : np.ndarray, shape (n_bodies, 3)
        Volume centroid of each body's principal bone alone, mm: the point whose motion the kinematic cost
        tracks (the lunate's without the triquetrum).
    grid_origin : np.ndarray, shape (n_bodies, 3)
        Each contact grid's origin, mm.
    grid_spacing : np.ndarray, shape (n_bodies,)
        Each contact grid's spacing, mm.
    grid_shape : np.ndarray, shape (n_bodies, 3)
        Each contact grid's (nx, ny, nz).
    grid_values : np.ndarray, shape (n_grid_values,)
        Signed distances, float32, mm, C-order per bone.
    grid_offsets : np.ndarray, shape (n_bodies + 1,)
        The offsets of each bone's grid values.
    sample_points, sample_normals : np.ndarray, shape (n_samples, 3)
        Contact samples on the sample bone's cartilage surface, mm, and their normals.
    sample_area : np.ndarray, shape (n_samples,)
        Each sample's area, mm².
    sample_thickness : np.ndarray, shape (n_samples,)
        Total cartilage thickness of both layers, mm.
    sample_offsets : np.ndarray, shape (n_pairs + 1,)
        The offsets of each pair's samples.
    contact_law : np.ndarray, shape (5,)
        Tri-linear pressure–strain law [e1, e2, k1, k2, k3] (strain, MPa).
    fibre_ligament : np.ndarray, shape (n_fibres,)
        Each fibre's ligament index.
    fibre_bones : np.ndarray, shape (n_fibres, 2)
        Each fibre's origin and insertion bone.
    fibre_origin, fibre_insertion : np.ndarray, shape (n_fibres, 3)
        Each fibre's ends, mm.
    reference_length : np.ndarray, shape (n_ligaments,)
        The mean neutral fibre length of each bundle, mm (for the RSC, of its longitudinal connectors).
    membrane_nodes : np.ndarray, shape (n_nodes, 3)
        The RSC membrane's nodes, mm.
    membrane_bone : np.ndarray, shape (n_nodes,)
        Each node's attached bone, or -1 if free.
    membrane_connectors : np.ndarray, shape (n_connectors, 2)
        The nodes each connector joins.
    membrane_kind : np.ndarray, shape (n_connectors,)
        0 along, 1 across.
    membrane_length : np.ndarray, shape (n_connectors,)
        Each connector's length, mm.
    report : dict, optional
        The build's report (timings, errors, counts).

    Raises
    ------
    InputError
        Arrays of another body or pair count than this version's (rebuild the model).
    """

    name: str
    source_hash: str
    vertices: np.ndarray
    vertex_offsets: np.ndarray
    faces: np.ndarray
    face_offsets: np.ndarray
    vertex_part: np.ndarray
    thickness: np.ndarray
    mass: np.ndarray
    com: np.ndarray
    inertia: np.ndarray
    centroid: np.ndarray
    grid_origin: np.ndarray
    grid_spacing: np.ndarray
    grid_shape: np.ndarray
    grid_values: np.ndarray
    grid_offsets: np.ndarray
    sample_points: np.ndarray
    sample_normals: np.ndarray
    sample_area: np.ndarray
    sample_thickness: np.ndarray
    sample_offsets: np.ndarray
    contact_law: np.ndarray
    fibre_ligament: np.ndarray
    fibre_bones: np.ndarray
    fibre_origin: np.ndarray
    fibre_insertion: np.ndarray
    reference_length: np.ndarray
    membrane_nodes: np.ndarray
    membrane_bone: np.ndarray
    membrane_connectors: np.ndarray
    membrane_kind: np.ndarray
    membrane_length: np.ndarray
    report: dict = field(default_factory=dict)

    def __post_init__(self):
        self._check_layout()
        for name, value in vars(self).items():
            if isinstance(value, np.ndarray):
                value.setflags(write=False)

    def _check_layout(self) -> None:
        """`InputError` naming the model and the field unless the per-body, per-pair and offset arrays
        have this version's body and pair counts (`BONES`, `PAIRS`) and the bone indices are bodies
        (the kernels do not check bounds: a model of another layout would corrupt memory)."""
        n, m = len(BONES), len(PAIRS)
        expected = {
            "mass": (n,),
            "com": (n, 3),
            "inertia": (n, 3, 3),
            "centroid": (n, 3),
            "grid_origin": (n, 3),
            "grid_spacing": (n,),
            "grid_shape": (n, 3),
            "vertex_offsets": (n + 1,),
            "face_offsets": (n + 1,),
            "grid_offsets": (n + 1,),
            "sample_offsets": (m + 1,),
        }
        for name, shape in expected.items():
            got = np.shape(getattr(self, name))
            if got != shape:
                raise InputError(
                    f"model {self.name!r}: {name} has shape {got}, but this version's {n} bodies ({', '.join(BONES)}) "
                    f"and {m} contact pairs need {shape}; rebuild the model"
                )
        for name in ("fibre_bones", "membrane_bone"):
            values = np.asarray(getattr(self, name))
            if values.size and (values.min() < (-1 if name == "membrane_bone" else 0) or values.max() >= n):
                raise InputError(
                    f"model {self.name!r}: {name} holds body index {int(values.max())} or {int(values.min())}, "
                    f"outside 0..{n - 1}; rebuild the model"
                )

    def bone_mesh(self, bone: str) -> tuple[np.ndarray, np.ndarray]:
        """(vertices (n, 3) mm, faces (m, 3)) of one bone, neutral pose."""
        i = BONES.index(bone)
        return (
            self.vertices[self.vertex_offsets[i] : self.vertex_offsets[i + 1]],
            self.faces[self.face_offsets[i] : self.face_offsets[i + 1]],
        )

    def part_mesh(self, part: str) -> tuple[np.ndarray, np.ndarray]:
        """(vertices (n, 3) mm, faces (m, 3)) of one of the nine bones (`PARTS`), neutral pose."""
        body = next(b for b in BONES if part in BODY_PARTS[b])
        v, f = self.bone_mesh(body)
        i = BONES.index(body)
        keep = self.vertex_part[self.vertex_offsets[i] : self.vertex_offsets[i + 1]] == BODY_PARTS[body].index(part)
        f = f[keep[f].all(axis=1)]
        new = np.cumsum(keep) - 1
        return v[keep], new[f]

    def bone_thickness(self, bone: str) -> np.ndarray:
        """Cartilage thickness (n,) mm on one bone's vertices."""
        i = BONES.index(bone)
        return self.thickness[self.vertex_offsets[i] : self.vertex_offsets[i + 1]]

    def grid(self, bone: str) -> np.ndarray:
        """The signed-distance values (nx, ny, nz) of one bone's contact grid."""
        i = BONES.index(bone)
        return self.grid_values[self.grid_offsets[i] : self.grid_offsets[i + 1]].reshape(self.grid_shape[i])

    def save(self, path: str | Path) -> None:
        """Write `path.npz` + `path.json`."""
        save_dataclass(self, path)

    @classmethod
    def load(cls, path: str | Path) -> "Model":
        """Read a model written by `save`."""
        return load_dataclass(cls, path)


def offsets(sizes: ArrayLike) -> np.ndarray:
    """Offsets of concatenated items of the given sizes.

    Parameters
    ----------
    sizes : array_like, shape (n,)
        The items' sizes.

    Returns
    -------
    np.ndarray, shape (n + 1,)
        int64: 0, then the cumulative sizes.
    """
    return np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
