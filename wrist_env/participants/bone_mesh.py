"""Bone mesh files of a participant folder: reading one (vertices mm, faces), validating it, and its solid part.

Carpal meshes are closed solids of one piece. A radius or ulna may also hold open parts (a
shaft cut short, as the built-in participants' are): those carry ligament
attachments only, while its closed parts carry contact and mass
(`solid_mask`); the radius needs a closed articular solid, the ulna none.

A carpal mesh of several connected pieces (an island left by segmentation) is refused, naming
each piece; `drop_islands` keeps its largest piece and drops pieces of at most `ISLAND_AREA_SHARE`
of its area. A radius or ulna may be of several pieces (the built-in radius is four: its
articular solid and the parts of its shaft), so their pieces are not checked.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import trimesh

from wrist_env.builder.surface import closed_face_mask
from wrist_env.errors import MeshError
from wrist_env.model import CARPALS

METRES_DIAGONAL_MM = 1.0  # a bounding-box diagonal below this is a bone in metres
CARPAL_DIAGONAL_MM = (5.0, 100.0)  # plausible bounding-box diagonal of a carpal bone
FOREARM_DIAGONAL_MM = (10.0, 600.0)  # ... of the radius or ulna (distal part or whole)
MIN_FACES = 100
# Faces per bone mesh. The build resolves ~0.5 mm (contact samples 1 mm apart, grids 0.5 mm, a 1 mm
# cartilage kernel), and the cartilage kernel's time and memory grow with the square of the vertex
# density: a lunate of 59,520 faces, half of it covered, took 1.5 GB in it, and of 238,080 faces 21 GB;
# P1 with carpals of 58,464–75,936 faces built in 174 s (129 s of it cartilage) at 1.4 GB. Built-in
# meshes: carpals 3,654–4,746 faces, radius 18,224 (articular solid and shaft), ulna 3,064.
MAX_FACES = {"carpal": 50_000, "forearm": 200_000}
SLIVER_REL = 1e-6
"""A face is degenerate when its least height (twice its area over its longest edge) is below this ×
the mesh's bounding-box diagonal: ~10× the float32 rounding of an STL's coordinates, so its normal is
still defined. The built-in carpals' least heights are 1.6e-5–2.7e-5 × their diagonals (0.4–0.9 µm)."""
FLAT_REL = 1e-3  # a mesh whose vertices lie within this × its diagonal of one plane is flat
ZERO_VOLUME_REL = 1e-4  # a closed mesh enclosing less than this × area^1.5 is a sheet (a sphere: 0.094)
ISLAND_AREA_SHARE = 0.1
"""`drop_islands` drops a carpal's pieces of at most this share of its largest piece's surface area: a
stray island of segmentation is far smaller (a 2 mm sphere beside a scaphoid: 0.8 %), while a bone in
two large pieces (a scaphoid waist fracture: each part a third or more) is no island, and stays refused."""


def read_bone_mesh(path: str | Path, bone: str, drop_islands: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) float64 mm and faces (m, 3) int64 of one bone mesh file, validated; MeshError if unusable.

    A file whose header or lines declare more than `MAX_FACES` faces is refused before it is read.
    drop_islands: a carpal of several pieces keeps its largest (`drop_small_islands`, with a warning
    naming the file and what was dropped) instead of being refused.
    """
    path = Path(path)
    _check_face_count(declared_faces(path), bone, str(path))
    try:
        mesh = trimesh.load_mesh(path, process=False)
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise MeshError(f"{path}: trimesh cannot read the {bone} mesh: {type(exc).__name__}: {exc}") from exc
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise MeshError(f"{path}: the {bone} file must hold a triangle mesh, but trimesh read {mesh!r}.")
    _check_face_count(len(mesh.faces), bone, str(path))
    _check_finite(np.asarray(mesh.vertices), np.asarray(mesh.faces), bone, str(path))
    mesh.merge_vertices()  # formats such as STL store every triangle's corners separately
    vertices, faces = np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64)
    if drop_islands and bone in CARPALS:
        vertices, faces = drop_small_islands(vertices, faces, bone, str(path))
    validate_bone_mesh(vertices, faces, bone, str(path))
    return vertices, faces


def validate_bone_mesh(vertices: np.ndarray, faces: np.ndarray, bone: str, source: str) -> None:
    """MeshError naming `source` unless the mesh is finite, in mm, not flat, non-degenerate, and closed
    (a radius or ulna may also hold open parts: see the module docstring) with outward faces."""
    _check_finite(vertices, faces, bone, source)
    if len(faces) < MIN_FACES:
        raise MeshError(f"{source}: the {bone} mesh must have at least {MIN_FACES} faces, but has {len(faces)}.")
    _check_face_count(len(faces), bone, source)
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise MeshError(
            f"{source}: face indices must be in [0, {len(vertices)}), but got [{faces.min()}, {faces.max()}]."
        )
    diagonal = float(np.linalg.norm(np.ptp(vertices, axis=0)))
    low, high = CARPAL_DIAGONAL_MM if bone in CARPALS else FOREARM_DIAGONAL_MM
    if diagonal < METRES_DIAGONAL_MM:
        raise MeshError(
            f"{source}: the {bone} mesh looks like metres: bounding-box diagonal {diagonal:.3g}; convert to mm (×1000)."
        )
    if not low <= diagonal <= high:
        raise MeshError(
            f"{source}: the {bone} mesh looks like the wrong unit: bounding-box diagonal {diagonal:.4g}, "
            f"expected {low:g}–{high:g} mm."
        )
    _check_not_flat(vertices, diagonal, bone, source)
    _check_degenerate(vertices, faces, diagonal, bone, source)
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    unique = mesh.unique_faces()
    if not unique.all():
        first = int(np.flatnonzero(~unique)[0])
        raise MeshError(
            f"{source}: the {bone} mesh has {int((~unique).sum())} duplicate faces "
            f"(first: face {first} = {faces[first].tolist()})."
        )
    if bone in CARPALS:
        _check_one_piece(vertices, faces, bone, source)
    closed = _closed_part(mesh, bone, source)
    if closed is None:
        return  # an ulna of open parts only: ligament attachments, no contact or mass
    if not closed.is_winding_consistent:
        raise MeshError(f"{source}: the {bone} mesh must have consistently wound faces, but it does not.")
    volume, area = float(closed.volume), float(closed.area)
    if abs(volume) <= ZERO_VOLUME_REL * area**1.5:
        raise MeshError(
            f"{source}: the {bone} mesh encloses almost no volume: {volume:.3g} mm³ inside {area:.4g} mm² of "
            f"surface (a flat or folded sheet, such as two coincident surfaces), not a solid."
        )
    if volume <= 0:
        raise MeshError(
            f"{source}: the {bone} mesh must have positive volume, but has {volume:.4g} mm³ "
            f"(inverted winding: faces point inward)."
        )


def pieces(vertices: np.ndarray, faces: np.ndarray) -> list[np.ndarray]:
    """The mesh's connected pieces as arrays of face indices, largest surface area first. Faces are
    connected through shared edges (vertices merged), so two pieces touching at a vertex are two."""
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    labels = trimesh.graph.connected_component_labels(mesh.face_adjacency, node_count=len(faces))
    groups = [np.flatnonzero(labels == k) for k in np.unique(labels)]
    area = mesh.area_faces
    return sorted(groups, key=lambda g: -float(area[g].sum()))


def drop_small_islands(
    vertices: np.ndarray, faces: np.ndarray, bone: str, source: str
) -> tuple[np.ndarray, np.ndarray]:
    """The mesh's largest piece (by surface area), its other pieces dropped with a warning naming `source`
    and each dropped piece; MeshError if another piece is larger than `ISLAND_AREA_SHARE` of it (two
    parts of a bone, not an island). A mesh of one piece is returned as it is."""
    found = pieces(vertices, faces)
    if len(found) == 1:
        return vertices, faces
    area = trimesh.Trimesh(vertices, faces, process=False).area_faces
    largest = float(area[found[0]].sum())
    share = float(area[found[1]].sum()) / largest
    if share > ISLAND_AREA_SHARE:
        raise MeshError(
            f"{source}: the {bone} mesh has {len(found)} pieces, and the second has {share:.0%} of the largest's "
            f"surface area, more than the {ISLAND_AREA_SHARE:.0%} drop_islands drops (two parts of a bone, not an "
            f"island): {_describe(vertices, faces, found)}; join or remove the pieces yourself."
        )
    kept = trimesh.Trimesh(vertices, faces[found[0]], process=False)
    kept.remove_unreferenced_vertices()
    warnings.warn(
        f"{source}: drop_islands: kept the {bone} mesh's largest piece, dropped {len(found) - 1} "
        f"({_describe(vertices, faces, found[1:])}).",
        stacklevel=2,
    )
    return np.asarray(kept.vertices, np.float64), np.asarray(kept.faces, np.int64)


def _check_one_piece(vertices: np.ndarray, faces: np.ndarray, bone: str, source: str) -> None:
    """MeshError naming `source` and each piece unless the mesh is one connected piece."""
    found = pieces(vertices, faces)
    if len(found) > 1:
        raise MeshError(
            f"{source}: the {bone} mesh must be one connected piece, but it has {len(found)}: "
            f"{_describe(vertices, faces, found)}; remove the stray pieces, or set drop_islands = true in "
            f"participant.toml to keep the largest."
        )


def _describe(vertices: np.ndarray, faces: np.ndarray, found: list[np.ndarray], limit: int = 5) -> str:
    """Pieces for a message: faces and extent (bounding-box diagonal, mm) of the first `limit`."""
    parts = []
    for group in found[:limit]:
        corners = vertices[np.unique(faces[group])]
        parts.append(f"{len(group):,} faces over {float(np.linalg.norm(np.ptp(corners, axis=0))):.3g} mm")
    more = f" and {len(found) - limit} more" if len(found) > limit else ""
    return "; ".join(parts) + more


def solid_mask(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Bool (n,): the vertices of a mesh's closed parts, which carry contact and mass (all of a carpal;
    the articular solid of a radius with an open shaft; none of an open ulna)."""
    solid = np.zeros(len(vertices), bool)
    solid[np.asarray(faces)[closed_face_mask(faces)]] = True
    return solid


def declared_faces(path: Path) -> int | None:
    """The number of faces a mesh file declares, found without loading it: a binary STL's or a PLY's
    header, or the facets of an ASCII STL and the face lines of an OBJ counted; None for other formats."""
    suffix = path.suffix.lower()
    if suffix == ".stl":
        return _stl_faces(path)
    if suffix == ".obj":
        return _count_token(path, b"\nf ")
    if suffix == ".ply":
        with open(path, "rb") as f:
            header = f.read(1 << 16).split(b"end_header")[0]
        found = re.search(rb"element\s+face\s+(\d+)", header)
        return int(found.group(1)) if found else None
    return None


def _stl_faces(path: Path) -> int:
    """The faces of a binary STL (its header's count, also when the file is padded past them) or of an
    ASCII STL (its facets); MeshError naming the file if it is neither (never handed to trimesh)."""
    with open(path, "rb") as f:
        head = f.read(84)
    size = path.stat().st_size
    count = int.from_bytes(head[80:84], "little") if len(head) == 84 else -1
    if size == 84 + 50 * count:
        return count
    facets = _count_token(path, b"endfacet")
    if facets or head.lstrip().startswith(b"solid"):
        return facets
    if count >= 0 and size > 84 + 50 * count:
        return count
    raise MeshError(
        f"{path}: not an STL file: neither binary (its header declares {count:,} faces, {84 + 50 * count:,} bytes, "
        f"but the file has {size:,}) nor ASCII (no facets)."
        if count >= 0
        else f"{path}: not an STL file: {size} bytes, shorter than a binary STL's 84-byte header, and no facets."
    )


def _count_token(path: Path, token: bytes, chunk: int = 1 << 24) -> int:
    """How often `token` occurs in a file, read in chunks."""
    count, tail = 0, b""
    with open(path, "rb") as f:
        while block := f.read(chunk):
            data = tail + block
            count += data.count(token)
            tail = data[-(len(token) - 1) :]
    return count


def _check_face_count(count: int | None, bone: str, source: str) -> None:
    kind = "carpal" if bone in CARPALS else "forearm"
    if count is not None and count > MAX_FACES[kind]:
        raise MeshError(
            f"{source}: the {bone} mesh has {count:,} faces, more than the {MAX_FACES[kind]:,} a {kind} mesh may "
            f"have (the build resolves ~0.5 mm; finer meshes only cost memory and time): decimate it to at most "
            f"{MAX_FACES[kind]:,} faces (e.g. MeshLab's quadric edge collapse decimation)."
        )


def _check_finite(vertices: np.ndarray, faces: np.ndarray, bone: str, source: str) -> None:
    """MeshError unless every vertex is finite, naming the first as the file holds it: in a file of
    separate triangles (STL: every face its own three corners) its triangle and corner, else its vertex."""
    bad = ~np.isfinite(vertices).all(axis=1)
    if not bad.any():
        return
    first = int(np.flatnonzero(bad)[0])
    value = vertices[first].tolist()
    if len(vertices) == faces.size and np.array_equal(np.ravel(faces), np.arange(faces.size)):
        what, where = "triangle corners", f"triangle {first // 3}, corner {first % 3} = {value}"
    else:
        used_by = np.flatnonzero((np.asarray(faces) == first).any(axis=1))[:3].tolist()
        what, where = "vertices", f"vertex {first} = {value}, used by faces {used_by}"
    raise MeshError(
        f"{source}: {bone} vertices must be finite, but {int(bad.sum())} {what} are not "
        f"(first: {where}; indices 0-based, in file order)."
    )


def _check_not_flat(vertices: np.ndarray, diagonal: float, bone: str, source: str) -> None:
    centred = vertices - vertices.mean(axis=0)
    normal = np.linalg.svd(centred, full_matrices=False)[2][-1]
    thickness = float(np.ptp(centred @ normal))
    if thickness <= FLAT_REL * diagonal:
        raise MeshError(
            f"{source}: the {bone} mesh is flat: its vertices lie within {thickness:.3g} mm of one plane "
            f"(bounding-box diagonal {diagonal:.4g} mm); a bone mesh must enclose a volume."
        )


def _check_degenerate(vertices: np.ndarray, faces: np.ndarray, diagonal: float, bone: str, source: str) -> None:
    """MeshError if a face has zero area or is a sliver (see `SLIVER_REL`)."""
    corners = vertices[faces]
    area = trimesh.triangles.area(corners)
    longest = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
    height = 2.0 * area / np.maximum(longest, np.finfo(float).tiny)
    bad = np.flatnonzero(height < SLIVER_REL * diagonal)
    if bad.size:
        k = int(bad[0])
        raise MeshError(
            f"{source}: the {bone} mesh has {bad.size} degenerate faces (zero area or slivers: least height below "
            f"{SLIVER_REL:g} × its diagonal = {SLIVER_REL * diagonal:.2g} mm) (first: face {k} = {faces[k].tolist()}, "
            f"area {area[k]:.2g} mm², height {height[k]:.2g} mm)."
        )


def _closed_part(mesh: trimesh.Trimesh, bone: str, source: str) -> trimesh.Trimesh | None:
    """The mesh's closed part: all of it for a carpal, which must be watertight; for a radius its closed
    components, which must form its articular solid; for an ulna those, or None if it has none."""
    _, counts = np.unique(mesh.edges_sorted, axis=0, return_counts=True)
    boundary, nonmanifold = int((counts == 1).sum()), int((counts > 2).sum())
    if not boundary and not nonmanifold:
        return mesh
    edges = f"{boundary} boundary edges and {nonmanifold} edges shared by more than two faces"
    if bone in CARPALS:
        raise MeshError(f"{source}: the {bone} mesh must be watertight, but it has {edges}.")
    closed = closed_face_mask(mesh.faces)
    if bone == "ulna" and not closed.any():
        return None
    part = trimesh.Trimesh(mesh.vertices, mesh.faces[closed], process=False)
    part.remove_unreferenced_vertices()
    diagonal = float(np.linalg.norm(np.ptp(part.vertices, axis=0))) if closed.any() else 0.0
    if bone == "radius" and diagonal < FOREARM_DIAGONAL_MM[0]:
        raise MeshError(
            f"{source}: the radius mesh must have a closed (watertight) part, its articular solid, of bounding-box "
            f"diagonal at least {FOREARM_DIAGONAL_MM[0]:g} mm, but its closed part spans {diagonal:.3g} mm "
            f"(it has {edges}); close the radius (open parts such as a cut shaft may stay open)."
        )
    return part
