"""Participant folders: `participant.toml`, five bone meshes and trial CSVs → ParticipantSource.

    my_wrist/
      participant.toml
      bones/radius.stl ulna.stl scaphoid.stl lunate.stl capitate.stl   (any format trimesh reads)
      trials/unresisted.csv trials/resisted.csv                         (see wrist_env.trial)

Meshes and trials are in the RCS, mm, static (neutral) pose. A left wrist
(side = "left") is mirrored to a right one on loading: vertices z → −z with
faces re-wound, trial transforms conjugated by diag(1, 1, −1, 1).
"""

from __future__ import annotations

import json
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from wrist_env.model import BONES
from wrist_env.errors import MeshError, ParticipantError
from wrist_env.trial import ROLES, Trial, mirror_trial, read_trial_csv, write_trial_csv

PARTICIPANT_FILE = "participant.toml"
REQUIRED_KEYS = ("name", "side", "units", "bones", "trials")
OPTIONAL_KEYS = ("sex", "age", "facet_type", "task", "frames")
SIDES = ("right", "left")
NAME_PATTERN = r"[A-Za-z0-9_]+"
TRIAL_NAME_PATTERN = r"[A-Za-z0-9_-]+"
CARPALS = ("scaphoid", "lunate", "capitate")
METRES_DIAGONAL_MM = 1.0  # a bounding-box diagonal below this is a bone in metres
CARPAL_DIAGONAL_MM = (5.0, 100.0)  # plausible bounding-box diagonal of a carpal bone
FOREARM_DIAGONAL_MM = (10.0, 600.0)  # ... of the radius or ulna (distal part or whole)
MIN_FACES = 100
ZERO_AREA_REL = 1e-12  # a face is degenerate below this × diagonal² (mm²)


@dataclass(frozen=True, eq=False)
class ParticipantSource:
    """A participant as given by the user, mirrored to a right wrist.

    meta: the optional fields of participant.toml (sex, age, facet_type, task, frames) plus
        side, the side of the files (the arrays here are always a right wrist).
    bones: {bone: (vertices of shape (n, 3) float64 mm, faces of shape (m, 3) int64)}, BONES order, RCS.
    trials: {name: Trial}. folder: where it was loaded from.
    """

    name: str
    meta: dict
    bones: dict[str, tuple[np.ndarray, np.ndarray]]
    trials: dict[str, Trial]
    folder: Path

    def __post_init__(self):
        if sorted(self.bones) != sorted(BONES):
            raise ParticipantError(f"participant {self.name!r}: bones must be {BONES}, but got {tuple(self.bones)}.")
        bones = {}
        for bone in BONES:
            vertices = np.array(self.bones[bone][0], dtype=np.float64)
            faces = np.array(self.bones[bone][1], dtype=np.int64)
            if vertices.ndim != 2 or vertices.shape[1] != 3 or faces.ndim != 2 or faces.shape[1] != 3:
                raise MeshError(
                    f"participant {self.name!r} bone {bone!r}: vertices and faces must have shapes (n, 3) and "
                    f"(m, 3), but got {vertices.shape} and {faces.shape}."
                )
            vertices.setflags(write=False)
            faces.setflags(write=False)
            bones[bone] = (vertices, faces)
        mismatched = [k for k, t in self.trials.items() if t.name != k]
        if mismatched:
            raise ParticipantError(f"participant {self.name!r}: trials must be keyed by their names, but {mismatched=}.")
        object.__setattr__(self, "bones", bones)
        object.__setattr__(self, "meta", dict(self.meta))
        object.__setattr__(self, "trials", dict(self.trials))
        object.__setattr__(self, "folder", Path(self.folder))


def load_participant_folder(path) -> ParticipantSource:
    """The participant in a folder, validated and mirrored to a right wrist; errors name the file and value."""
    folder = Path(path)
    if not folder.is_dir():
        raise ParticipantError(f"participant folder {folder} does not exist or is not a folder.")
    toml_path = folder / PARTICIPANT_FILE
    if not toml_path.is_file():
        raise ParticipantError(f"{toml_path} does not exist; a participant folder needs a {PARTICIPANT_FILE}.")
    try:
        with open(toml_path, "rb") as f:
            config = tomllib.load(f)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ParticipantError(f"{toml_path}: TOML syntax error: {exc}") from exc

    unknown = [k for k in config if k not in REQUIRED_KEYS + OPTIONAL_KEYS]
    if unknown:
        raise ParticipantError(f"{toml_path}: keys must be among {REQUIRED_KEYS + OPTIONAL_KEYS}, but got {unknown}.")
    missing = [k for k in REQUIRED_KEYS if k not in config]
    if missing:
        raise ParticipantError(f"{toml_path}: required keys {missing} are missing.")
    name = config["name"]
    if not isinstance(name, str) or not re.fullmatch(NAME_PATTERN, name):
        raise ParticipantError(f"{toml_path}: name must match {NAME_PATTERN}, but got {name!r}.")
    if config["units"] != "mm":
        raise ParticipantError(
            f"{toml_path}: units must be \"mm\", but got {config['units']!r}; convert meshes and trials to mm."
        )
    if config["side"] not in SIDES:
        raise ParticipantError(f"{toml_path}: side must be one of {SIDES}, but got {config['side']!r}.")
    meta = _check_meta(config, toml_path)

    bone_table = _check_table(config, "bones", toml_path)
    absent = [b for b in BONES if b not in bone_table]
    extra = [b for b in bone_table if b not in BONES]
    if absent or extra:
        raise ParticipantError(f"{toml_path}: [bones] must list exactly {BONES}, but {absent=} and {extra=}.")
    bones = {b: read_bone_mesh(_listed_file(folder, bone_table[b], f"bones.{b}", toml_path), b) for b in BONES}

    trial_table = _check_table(config, "trials", toml_path)
    trials = {}
    for trial_name, entry in trial_table.items():
        where = f"[trials.{trial_name}]"
        if not re.fullmatch(TRIAL_NAME_PATTERN, trial_name):
            raise ParticipantError(f"{toml_path}: trial names must match {TRIAL_NAME_PATTERN}, but got {trial_name!r}.")
        if not isinstance(entry, dict) or sorted(entry) != ["file", "role"]:
            keys = sorted(entry) if isinstance(entry, dict) else entry
            raise ParticipantError(f"{toml_path}: {where} must have exactly the keys file and role, but got {keys!r}.")
        if entry["role"] not in ROLES:
            raise ParticipantError(f"{toml_path}: {where} role must be one of {ROLES}, but got {entry['role']!r}.")
        file = _listed_file(folder, entry["file"], f"{where} file", toml_path)
        trials[trial_name] = read_trial_csv(file, trial_name, entry["role"], n_frames=meta.get("frames"))
    if not any(t.role == "calibrate" for t in trials.values()):
        roles = {k: t.role for k, t in trials.items()}
        raise ParticipantError(f"{toml_path}: at least one trial must have role \"calibrate\", but got {roles}.")

    if config["side"] == "left":
        bones = {b: mirror_mesh(*vf) for b, vf in bones.items()}
        trials = {k: mirror_trial(t) for k, t in trials.items()}
    return ParticipantSource(name, meta, bones, trials, folder)


def write_participant_folder(source: ParticipantSource, path) -> Path:
    """Write `source` as a participant folder (STL meshes, trial CSVs, participant.toml); returns the folder.

    Files are written for meta["side"] (default "right"), so loading the folder gives `source` back
    (mesh vertices to float32 precision, as STL stores them).
    """
    folder = Path(path)
    (folder / "bones").mkdir(parents=True, exist_ok=True)
    (folder / "trials").mkdir(parents=True, exist_ok=True)
    side = source.meta.get("side", "right")
    if side not in SIDES:
        raise ParticipantError(f"participant {source.name!r}: meta side must be one of {SIDES}, but got {side!r}.")
    lines = [f"name = {_toml_value(source.name)}", f"side = {_toml_value(side)}", 'units = "mm"']
    lines += [f"{k} = {_toml_value(source.meta[k])}" for k in OPTIONAL_KEYS if k in source.meta]
    lines += ["", "[bones]"]
    for bone, (vertices, faces) in source.bones.items():
        if side == "left":
            vertices, faces = mirror_mesh(vertices, faces)
        trimesh.Trimesh(vertices, faces, process=False).export(folder / "bones" / f"{bone}.stl")
        lines.append(f"{bone} = {_toml_value(f'bones/{bone}.stl')}")
    for trial_name, trial in source.trials.items():
        write_trial_csv(mirror_trial(trial) if side == "left" else trial, folder / "trials" / f"{trial_name}.csv")
        lines += ["", f"[trials.{trial_name}]", f"file = {_toml_value(f'trials/{trial_name}.csv')}",
                  f"role = {_toml_value(trial.role)}"]
    (folder / PARTICIPANT_FILE).write_text("\n".join(lines) + "\n", encoding="utf-8")
    return folder


def mirror_mesh(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The mirror-image mesh (z → −z), faces re-wound so the normals still point outward."""
    return np.asarray(vertices, np.float64) * [1.0, 1.0, -1.0], np.asarray(faces, np.int64)[:, [0, 2, 1]]


def read_bone_mesh(path, bone: str) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) float64 mm and faces (m, 3) int64 of one bone mesh file, validated; MeshError if unusable."""
    path = Path(path)
    try:
        mesh = trimesh.load_mesh(path, process=False)
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise MeshError(f"{path}: trimesh cannot read the {bone} mesh: {type(exc).__name__}: {exc}") from exc
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise MeshError(f"{path}: the {bone} file must hold a triangle mesh, but trimesh read {mesh!r}.")
    _check_finite(np.asarray(mesh.vertices), bone, str(path))
    mesh.merge_vertices()  # formats such as STL store every triangle's corners separately
    vertices, faces = np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64)
    validate_bone_mesh(vertices, faces, bone, str(path))
    return vertices, faces


def validate_bone_mesh(vertices: np.ndarray, faces: np.ndarray, bone: str, source: str) -> None:
    """MeshError naming `source` unless the mesh is finite, in mm, non-degenerate, watertight and outward."""
    _check_finite(vertices, bone, source)
    if len(faces) < MIN_FACES:
        raise MeshError(f"{source}: the {bone} mesh must have at least {MIN_FACES} faces, but has {len(faces)}.")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise MeshError(f"{source}: face indices must be in [0, {len(vertices)}), but got [{faces.min()}, {faces.max()}].")
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
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    zero = np.flatnonzero(mesh.area_faces <= ZERO_AREA_REL * diagonal**2)
    if zero.size:
        raise MeshError(
            f"{source}: the {bone} mesh has {zero.size} zero-area faces (first: face {zero[0]} = {faces[zero[0]].tolist()})."
        )
    unique = mesh.unique_faces()
    if not unique.all():
        first = int(np.flatnonzero(~unique)[0])
        raise MeshError(
            f"{source}: the {bone} mesh has {int((~unique).sum())} duplicate faces "
            f"(first: face {first} = {faces[first].tolist()})."
        )
    _, counts = np.unique(mesh.edges_sorted, axis=0, return_counts=True)
    boundary, nonmanifold = int((counts == 1).sum()), int((counts > 2).sum())
    if boundary or nonmanifold:
        raise MeshError(
            f"{source}: the {bone} mesh must be watertight, but it has {boundary} boundary edges "
            f"and {nonmanifold} edges shared by more than two faces."
        )
    if not mesh.is_winding_consistent:
        raise MeshError(f"{source}: the {bone} mesh must have consistently wound faces, but it does not.")
    if mesh.volume <= 0:
        raise MeshError(
            f"{source}: the {bone} mesh must have positive volume, but has {mesh.volume:.4g} mm³ "
            f"(inverted winding: faces point inward)."
        )


def _check_finite(vertices: np.ndarray, bone: str, source: str) -> None:
    bad = ~np.isfinite(vertices).all(axis=1)
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        raise MeshError(
            f"{source}: {bone} vertices must be finite, but {int(bad.sum())} are not "
            f"(first: vertex {first} = {vertices[first].tolist()})."
        )


def _check_meta(config: dict, toml_path: Path) -> dict:
    """The optional fields (plus side), type-checked."""
    meta = {"side": config["side"]}
    for key in ("sex", "facet_type", "task"):
        if key in config:
            if not isinstance(config[key], str):
                raise ParticipantError(f"{toml_path}: {key} must be a string, but got {config[key]!r}.")
            meta[key] = config[key]
    if "age" in config:
        age = config["age"]
        if isinstance(age, bool) or not isinstance(age, (int, float)) or not 0 < age < 150:
            raise ParticipantError(f"{toml_path}: age must be a number of years in (0, 150), but got {age!r}.")
        meta["age"] = age
    if "frames" in config:
        frames = config["frames"]
        if isinstance(frames, bool) or not isinstance(frames, int) or frames < 2:
            raise ParticipantError(f"{toml_path}: frames must be an integer >= 2, but got {frames!r}.")
        meta["frames"] = frames
    return meta


def _check_table(config: dict, key: str, toml_path: Path) -> dict:
    if not isinstance(config[key], dict) or not config[key]:
        raise ParticipantError(f"{toml_path}: [{key}] must be a non-empty table, but got {config[key]!r}.")
    return config[key]


def _listed_file(folder: Path, relative, where: str, toml_path: Path) -> Path:
    """The file a participant.toml entry names, relative to the folder and inside it once links are
    resolved; ParticipantError if absent or outside (its content is never read then)."""
    if not isinstance(relative, str):
        raise ParticipantError(f"{toml_path}: {where} must be a path string, but got {relative!r}.")
    if Path(relative).is_absolute():
        raise ParticipantError(f"{toml_path}: {where} = {relative!r} must be relative to the participant folder.")
    file = folder / relative
    root = folder.resolve()
    if not file.resolve().is_relative_to(root):
        raise ParticipantError(f"{toml_path}: {where} = {relative!r} resolves outside the participant folder "
                               f"{root} (through '..' or a link); refused, not read.")
    if not file.is_file():
        raise ParticipantError(f"{toml_path}: {where} = {relative!r}, but {file} does not exist.")
    return file


def _toml_value(value) -> str:
    """A TOML literal of a string, integer or finite float."""
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        return str(int(value))
    if isinstance(value, (float, np.floating)) and np.isfinite(value):
        return repr(float(value))
    raise ParticipantError(f"participant.toml values must be strings or finite numbers, but got {value!r}.")
