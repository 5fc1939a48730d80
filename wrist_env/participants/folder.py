"""Participant folders: `participant.toml`, five bone meshes and trial CSVs → ParticipantSource.

    my_wrist/
      participant.toml
      bones/radius.stl ulna.stl scaphoid.stl lunate.stl capitate.stl   (any format trimesh reads)
           [triquetrum.stl trapezium.stl trapezoid.stl hamate.stl]    (optional: else the template's)
      trials/unresisted.csv trials/resisted.csv                         (see wrist_env.trial)

Meshes and trials are in the RCS, mm, static (neutral) pose. A left wrist
(side = "left") is mirrored to a right one on loading: vertices z → −z with
faces re-wound, trial transforms conjugated by diag(1, 1, −1, 1).

Each bone mesh file is read and validated by `wrist_env.participants.bone_mesh`; a carpal of
several pieces is refused unless `drop_islands = true` (then its largest piece is kept). Two bones
listed with one file (the same path, or files of identical bytes) are refused before any is read.
"""

from __future__ import annotations

import json
import os
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh
from scipy.spatial import cKDTree

from wrist_env.builder.params import check_ulnar_variance
from wrist_env.errors import InputError, MeshError, ParticipantError
from wrist_env.io import sha256_file
from wrist_env.limits import MAX_TRIAL_FRAMES
from wrist_env.model import OPTIONAL_BONES, SUPPLIED
from wrist_env.participants.bone_mesh import read_bone_mesh
from wrist_env.trial import ROLES, Trial, mirror_trial, read_trial_csv, write_trial_csv

PARTICIPANT_FILE = "participant.toml"
REQUIRED_KEYS = ("name", "side", "units", "bones", "trials")
OPTIONAL_KEYS = ("sex", "age", "facet_type", "task", "frames", "drop_islands", "ulnar_variance_mm")
SIDES = ("right", "left")
NAME_PATTERN = r"[A-Za-z0-9_]{1,64}"
TRIAL_NAME_PATTERN = r"[A-Za-z0-9_-]{1,64}"
"""Names become parts of file names (the model cache, run logs): 64 characters at most."""


@dataclass(frozen=True, eq=False)
class ParticipantSource:
    """A participant as given by the user, mirrored to a right wrist.

    meta: the optional fields of participant.toml (sex, age, facet_type, task, frames, drop_islands,
        ulnar_variance_mm) plus
        side, the side of the files (the arrays here are always a right wrist).
    bones: {bone: (vertices of shape (n, 3) float64 mm, faces of shape (m, 3) int64)}, RCS: the `SUPPLIED`
        bones, then those of `OPTIONAL_BONES` the folder gives, in those orders.
    trials: {name: Trial}. folder: where it was loaded from.
    """

    name: str
    meta: dict
    bones: dict[str, tuple[np.ndarray, np.ndarray]]
    trials: dict[str, Trial]
    folder: Path

    def __post_init__(self):
        order = SUPPLIED + tuple(b for b in OPTIONAL_BONES if b in self.bones)
        if sorted(self.bones) != sorted(order):
            raise ParticipantError(
                f"participant {self.name!r}: bones must be {SUPPLIED}, and may be any of {OPTIONAL_BONES} too, "
                f"but got {tuple(self.bones)}."
            )
        bones = {}
        for bone in order:
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
            raise ParticipantError(
                f"participant {self.name!r}: trials must be keyed by their names, but {mismatched=}."
            )
        object.__setattr__(self, "bones", bones)
        object.__setattr__(self, "meta", dict(self.meta))
        object.__setattr__(self, "trials", dict(self.trials))
        object.__setattr__(self, "folder", Path(self.folder))


def load_participant_folder(path: str | Path) -> ParticipantSource:
    """The participant in a folder, validated and mirrored to a right wrist; errors name the file and value."""
    folder = Path(path)
    resolved(folder)  # a null byte or a symlink loop: one line, not a traceback
    if not folder.is_dir():
        raise ParticipantError(f"participant folder {folder} does not exist or is not a folder.")
    toml_path = folder / PARTICIPANT_FILE
    if not toml_path.is_file():
        raise ParticipantError(f"{toml_path} does not exist; a participant folder needs a {PARTICIPANT_FILE}.")
    try:
        config = tomllib.loads(toml_path.read_bytes().decode("utf-8-sig"))  # a byte-order mark is dropped
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
            f'{toml_path}: units must be "mm", but got {config["units"]!r}; convert meshes and trials to mm.'
        )
    if config["side"] not in SIDES:
        raise ParticipantError(f"{toml_path}: side must be one of {SIDES}, but got {config['side']!r}.")
    meta = _check_meta(config, toml_path)

    bone_table = _check_table(config, "bones", toml_path)
    absent = [b for b in SUPPLIED if b not in bone_table]
    extra = [b for b in bone_table if b not in SUPPLIED + OPTIONAL_BONES]
    if absent or extra:
        raise ParticipantError(
            f"{toml_path}: [bones] must list {SUPPLIED} and may list any of {OPTIONAL_BONES}, "
            f"but {absent=} and {extra=}."
        )
    listed = SUPPLIED + tuple(b for b in OPTIONAL_BONES if b in bone_table)
    files = {b: _listed_file(folder, bone_table[b], f"bones.{b}", toml_path) for b in listed}
    _check_distinct_files(files, toml_path)
    drop = meta.get("drop_islands", False)
    bones = {b: read_bone_mesh(files[b], b, drop_islands=drop) for b in listed}
    _check_arrangement(bones, toml_path)
    _check_given(bones, files, toml_path)

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
    roles = {k: t.role for k, t in trials.items()}
    if list(roles.values()).count("calibrate") != 1:
        raise ParticipantError(f'{toml_path}: exactly one trial must have role "calibrate", but got {roles}.')

    if config["side"] == "left":
        bones = {b: mirror_mesh(*vf) for b, vf in bones.items()}
        trials = {k: mirror_trial(t) for k, t in trials.items()}
    return ParticipantSource(name, meta, bones, trials, folder)


def write_participant_folder(source: ParticipantSource, path: str | Path) -> Path:
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
        lines += [
            "",
            f"[trials.{trial_name}]",
            f"file = {_toml_value(f'trials/{trial_name}.csv')}",
            f"role = {_toml_value(trial.role)}",
        ]
    (folder / PARTICIPANT_FILE).write_text("\n".join(lines) + "\n", encoding="utf-8")
    return folder


def mirror_mesh(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The mirror-image mesh (z → −z), faces re-wound so the normals still point outward."""
    return np.asarray(vertices, np.float64) * [1.0, 1.0, -1.0], np.asarray(faces, np.int64)[:, [0, 2, 1]]


def resolved(path: str | Path) -> Path:
    """`path` with links resolved (it need not exist); ParticipantError naming it if it holds a null byte
    or runs into a symlink loop (`Path.resolve` raises ValueError, or RuntimeError (OSError from Python 3.13))."""
    text = os.fspath(path)
    if "\0" in str(text):
        raise ParticipantError(f"participant folder {str(text)!r} contains a null byte.")
    try:
        return Path(path).resolve()
    except (RuntimeError, OSError) as exc:
        raise ParticipantError(f"participant folder {text} cannot be resolved: {exc}.") from None


def _check_distinct_files(files: dict[str, Path], toml_path: Path) -> None:
    """ParticipantError naming both bones and the file(s) if two bones are listed with one file: the same
    path once links are resolved, or files of identical bytes (SHA-256, of files of equal size) — a bone
    copied under another name, which the build would only refuse minutes later as implausible joint spaces."""
    paths = {b: f.resolve() for b, f in files.items()}
    sizes = [p.stat().st_size for p in paths.values()]
    seen: dict[tuple, str] = {}
    for (bone, path), size in zip(paths.items(), sizes):
        keys = [("path", path)] + ([("bytes", sha256_file(path))] if sizes.count(size) > 1 else [])
        for key in keys:
            other = seen.setdefault(key, bone)
            if other != bone:
                same = (
                    f"the same file {files[other]}"
                    if key[0] == "path"
                    else f"files of identical content ({files[other]} and {files[bone]})"
                )
                raise ParticipantError(
                    f"{toml_path}: bones.{other} and bones.{bone} are {same}; each bone needs its own mesh."
                )


def _centres_and_radial(bones: dict) -> tuple[dict, np.ndarray]:
    """Each bone's vertex centroid (mm), and the unit ulna → radius direction across the forearm (RCS y
    dropped: the shafts' lengths do not count), from the files' own centroids, so either side passes."""
    centre = {b: np.asarray(v, float).mean(axis=0) for b, (v, _) in bones.items()}
    radial = centre["radius"] - centre["ulna"]
    radial[1] = 0.0
    return centre, radial / max(float(np.linalg.norm(radial)), 1e-12)


def _check_arrangement(bones: dict, toml_path: Path) -> None:
    """ParticipantError naming both entries if two carpals look swapped: the scaphoid must lie radial
    of the lunate (along the ulna → radius direction of the files' own centroids, so either side
    passes) and the capitate distal of the lunate (RCS −y)."""
    centre, radial = _centres_and_radial(bones)
    offset = float((centre["scaphoid"] - centre["lunate"]) @ radial)
    if offset < 0.0:
        raise ParticipantError(
            f"{toml_path}: bones.scaphoid and bones.lunate look swapped: the scaphoid's centroid is "
            f"{-offset:.1f} mm ulnar of the lunate's, and a scaphoid lies radial of it (from the radius and "
            f"ulna as listed); check [bones]."
        )
    proximal = float(centre["capitate"][1] - centre["lunate"][1])
    if proximal > 0.0:
        raise ParticipantError(
            f"{toml_path}: bones.capitate and bones.lunate look swapped: the capitate's centroid is "
            f"{proximal:.1f} mm proximal of the lunate's (RCS +y), and a capitate lies distal of it; check [bones]."
        )


GIVEN_NEIGHBOURS = {
    "triquetrum": ("lunate", -1),
    "hamate": ("capitate", -1),
    "trapezium": ("scaphoid", +1),
    "trapezoid": ("capitate", +1),
}
"""Each optional bone (`OPTIONAL_BONES`), a supplied bone it articulates with (the lunotriquetral,
capitohamate, scaphotrapezial and trapezoid–capitate joints) and its side of that bone's centroid (+1
radial, −1 ulnar; on the template 7–12 mm off that centroid's line, away from the neighbour)."""
GIVEN_REACH_MM = 5.0
"""How near (mm) an optional bone's mesh must come to its neighbour's (`GIVEN_NEIGHBOURS`). Articulating
carpals are 1–3 mm apart (the build refuses neutral joint spaces outside 0.5–3.0 mm); 5 mm leaves room
for coarse meshes and still refuses a bone in another frame or unit."""


def _check_given(bones: dict, files: dict, toml_path: Path) -> None:
    """ParticipantError naming the entry and its file if an optional bone does not sit where its anatomy
    puts it: beyond `GIVEN_REACH_MM` of the bone it articulates with, or on the wrong side of it (the
    radial direction from the radius and ulna as listed, as in `_check_arrangement`)."""
    centre, radial = _centres_and_radial(bones)
    for bone, (neighbour, side) in GIVEN_NEIGHBOURS.items():
        if bone not in bones:
            continue
        gap = float(cKDTree(np.asarray(bones[neighbour][0], float)).query(np.asarray(bones[bone][0], float))[0].min())
        if gap > GIVEN_REACH_MM:
            raise ParticipantError(
                f"{toml_path}: bones.{bone} ({files[bone].name}) comes no nearer than {gap:.1f} mm to the "
                f"{neighbour}, with which a {bone} articulates (at most {GIVEN_REACH_MM:g} mm: "
                "folder.GIVEN_REACH_MM); is it in the RCS, mm and static pose of the other bones?"
            )
        offset = float((centre[bone] - centre[neighbour]) @ radial) * side
        if offset < 0.0:
            where, should = ("ulnar", "radial") if side > 0 else ("radial", "ulnar")
            raise ParticipantError(
                f"{toml_path}: bones.{bone} ({files[bone].name}) has its centroid {-offset:.1f} mm {where} of "
                f"the {neighbour}'s, and a {bone} lies {should} of it; check [bones]."
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
        if isinstance(frames, bool) or not isinstance(frames, int) or not 2 <= frames <= MAX_TRIAL_FRAMES:
            raise ParticipantError(
                f"{toml_path}: frames must be an integer in [2, {MAX_TRIAL_FRAMES:,}] (limits.MAX_TRIAL_FRAMES), "
                f"but got {frames!r}."
            )
        meta["frames"] = frames
    if "drop_islands" in config:
        if not isinstance(config["drop_islands"], bool):
            raise ParticipantError(
                f"{toml_path}: drop_islands must be true or false, but got {config['drop_islands']!r}."
            )
        meta["drop_islands"] = config["drop_islands"]
    if "ulnar_variance_mm" in config:  # the build seats the ulna there (BuildParams.ulnar_variance_mm)
        try:
            meta["ulnar_variance_mm"] = check_ulnar_variance(config["ulnar_variance_mm"])
        except InputError as exc:
            raise ParticipantError(f"{toml_path}: {exc}.") from None
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
    try:
        inside = file.resolve().is_relative_to(root)
    except (ValueError, RuntimeError, OSError) as exc:  # a null byte, a symlink loop
        raise ParticipantError(f"{toml_path}: {where} = {relative!r} cannot be resolved ({exc}).") from None
    if not inside:
        raise ParticipantError(
            f"{toml_path}: {where} = {relative!r} resolves outside the participant folder "
            f"{root} (through '..' or a link); refused, not read."
        )
    if not file.is_file():
        what = "is a folder" if file.is_dir() else "is not a regular file" if file.exists() else "does not exist"
        raise ParticipantError(f"{toml_path}: {where} = {relative!r}, but {file} {what}.")
    return file


def _toml_value(value) -> str:
    """A TOML literal of a string, boolean, integer or finite float."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        return str(int(value))
    if isinstance(value, (float, np.floating)) and np.isfinite(value):
        return repr(float(value))
    raise ParticipantError(f"participant.toml values must be strings, booleans or finite numbers, but got {value!r}.")
