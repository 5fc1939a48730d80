"""Participant folders: round trip, left-wrist mirroring, and one test per validation rule."""

import dataclasses
import os
import re
from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from wrist_env.builder.params import BuildParams
from wrist_env.errors import MeshError, ParticipantError, TrialError
from wrist_env.model import SUPPLIED
from wrist_env.participants import bone_mesh as folder_module
from wrist_env.participants import builtin, registry
from wrist_env.participants.folder import ParticipantSource, load_participant_folder, write_participant_folder
from wrist_env.trial import MIRROR, Trial

BONES = ("radius", "ulna", "scaphoid", "lunate", "capitate")
# carpal ellipsoid semi-axes and centres (mm, RCS: x volar, y proximal, z radial)
CARPALS = {
    "scaphoid": ((12, 7, 6), (2, -10, 10)),
    "lunate": ((9, 7, 8), (0, -10, -2)),
    "capitate": ((8, 13, 7), (0, -28, 3)),
}


def bone_meshes() -> dict:
    """{bone: (vertices, faces)}: icosphere ellipsoids for carpals, capsules along y for radius and ulna."""
    out = {}
    for bone, z in (("radius", 8.0), ("ulna", -20.0)):
        mesh = trimesh.creation.capsule(height=40.0, radius=10.0 if bone == "radius" else 6.0, count=[16, 16])
        mesh.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [1, 0, 0]))
        mesh.apply_translation([0.0, 30.0, z])
        out[bone] = (mesh.vertices, mesh.faces)
    for bone, (axes, centre) in CARPALS.items():
        mesh = trimesh.creation.icosphere(subdivisions=2)
        mesh.apply_scale(axes)
        mesh.apply_translation(centre)
        out[bone] = (mesh.vertices, mesh.faces)
    return out


def trial_transforms(peak_deg: float) -> np.ndarray:
    """Array of shape (5, 15, 4, 4): carpals rotate about their centres by shares of a flexion/deviation cycle."""
    angles = peak_deg * np.sin(np.linspace(0, 2 * np.pi, 15))
    out = np.tile(np.eye(4), (5, 15, 1, 1))
    for b, bone in enumerate(BONES[2:], start=2):
        share = {"scaphoid": 0.8, "lunate": 0.5, "capitate": 1.0}[bone]
        rot = Rotation.from_euler("ZX", np.c_[angles, 0.3 * angles] * share, degrees=True).as_matrix()
        c = np.array(CARPALS[bone][1], float)
        out[b, :, :3, :3], out[b, :, :3, 3] = rot, c - rot @ c
    return out


def make_source(tmp_path, side: str = "right") -> ParticipantSource:
    trials = {
        "unresisted": Trial("unresisted", "calibrate", BONES, trial_transforms(30.0)),
        "resisted": Trial("resisted", "validate", BONES, trial_transforms(20.0)),
    }
    meta = {"side": side, "sex": "female", "age": 41, "facet_type": "I", "task": "flexion-extension", "frames": 15}
    return ParticipantSource("P7", meta, bone_meshes(), trials, tmp_path)


@pytest.fixture
def folder(tmp_path):
    return write_participant_folder(make_source(tmp_path), tmp_path / "my_wrist")


def edit_toml(folder, old: str, new: str) -> None:
    path = folder / "participant.toml"
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))


def replace_mesh(folder, bone: str, vertices, faces, name: str | None = None) -> None:
    path = folder / "bones" / (name or f"{bone}.stl")
    trimesh.Trimesh(vertices, faces, process=False).export(path)
    if name:
        edit_toml(folder, f'"bones/{bone}.stl"', f'"bones/{name}"')


def raises(error, path, value: str):
    """pytest.raises(error) whose message names the file and then the value."""
    return pytest.raises(error, match=f"(?s){re.escape(str(path))}.*{value}")


def assert_same_triangles(a, b, atol):
    """Two (vertices, faces) meshes have the same triangles in the same order."""
    np.testing.assert_allclose(a[0][a[1]], b[0][b[1]], atol=atol, rtol=0)


def test_round_trip(tmp_path, folder):
    source = make_source(tmp_path)
    loaded = load_participant_folder(folder)
    assert loaded.name == "P7" and loaded.folder == folder
    assert loaded.meta == source.meta
    assert list(loaded.bones) == list(BONES)
    for bone in BONES:
        vertices, faces = loaded.bones[bone]
        assert vertices.dtype == np.float64 and faces.dtype == np.int64
        assert not vertices.flags.writeable and not faces.flags.writeable
        assert len(vertices) == len(source.bones[bone][0])  # STL corners merged back to shared vertices
        assert_same_triangles(loaded.bones[bone], source.bones[bone], atol=1e-5)  # STL stores float32
    assert list(loaded.trials) == ["unresisted", "resisted"]
    for name, trial in source.trials.items():
        assert (loaded.trials[name].role, loaded.trials[name].bones) == (trial.role, trial.bones)
        np.testing.assert_array_equal(loaded.trials[name].transforms, trial.transforms)

    again = load_participant_folder(write_participant_folder(loaded, tmp_path / "copy"))
    assert again.meta == loaded.meta
    for bone in BONES:
        np.testing.assert_array_equal(again.bones[bone][0], loaded.bones[bone][0])
        np.testing.assert_array_equal(again.bones[bone][1], loaded.bones[bone][1])


def test_left_folder_loads_as_mirror_image(tmp_path, folder):
    right = load_participant_folder(folder)
    edit_toml(folder, 'side = "right"', 'side = "left"')
    left = load_participant_folder(folder)
    assert left.meta["side"] == "left"
    for bone in BONES:
        vertices, faces = left.bones[bone]
        mesh = trimesh.Trimesh(vertices, faces, process=False)
        assert mesh.is_watertight and mesh.volume == pytest.approx(trimesh.Trimesh(*right.bones[bone]).volume)
        assert mesh.volume > 0
        expected = right.bones[bone][0][right.bones[bone][1]][:, [0, 2, 1]] * [1, 1, -1]
        np.testing.assert_array_equal(vertices[faces], expected)
    for name, trial in left.trials.items():
        np.testing.assert_allclose(np.linalg.det(trial.transforms[..., :3, :3]), 1.0, atol=1e-9)
        # a point of the mirrored bone follows the mirror image of the right bone's path
        point = np.array([1.0, -10.0, 9.0, 1.0])
        moved = right.trials[name].pose("scaphoid") @ point
        np.testing.assert_allclose(trial.pose("scaphoid") @ (MIRROR @ point), moved @ MIRROR, atol=1e-12)


def test_left_source_round_trips(tmp_path):
    source = make_source(tmp_path, side="left")
    folder = write_participant_folder(source, tmp_path / "left")
    on_disk = trimesh.load_mesh(folder / "bones" / "scaphoid.stl")
    assert on_disk.bounds[0, 2] == pytest.approx(-16.0, abs=1e-4)  # scaphoid z in [4, 16] mirrored to [-16, -4]
    loaded = load_participant_folder(folder)
    assert_same_triangles(loaded.bones["scaphoid"], source.bones["scaphoid"], atol=1e-5)
    np.testing.assert_allclose(
        loaded.trials["unresisted"].transforms, source.trials["unresisted"].transforms, atol=1e-15
    )


# --- one test per error ---------------------------------------------------------------


def test_missing_folder(tmp_path):
    with raises(ParticipantError, tmp_path / "nowhere", "does not exist"):
        load_participant_folder(tmp_path / "nowhere")


TOML = "participant.toml"
BAD_TOML = [
    # (id, text replaced in participant.toml, replacement, error, file named, message)
    ("syntax", 'name = "P7"', 'name = "P7', ParticipantError, TOML, r"TOML syntax error: .*line 1"),
    ("required key", 'units = "mm"\n', "", ParticipantError, TOML, r"required keys \['units'\] are missing"),
    ("unknown key", "frames = 15", "frame = 15", ParticipantError, TOML, r"but got \['frame'\]"),
    ("units", 'units = "mm"', 'units = "m"', ParticipantError, TOML, "units must be \"mm\", but got 'm'"),
    ("side", 'side = "right"', 'side = "R"', ParticipantError, TOML, "side must be one of.*got 'R'"),
    ("name", 'name = "P7"', 'name = "P-7"', ParticipantError, TOML, "name must match.*got 'P-7'"),
    ("name too long", 'name = "P7"', f'name = "{"P" * 300}"', ParticipantError, TOML, r"name must match .*\{1,64\}"),
    ("age", "age = 41", 'age = "41"', ParticipantError, TOML, "age must be a number.*got '41'"),
    ("bone entry", 'lunate = "bones/lunate.stl"\n', "", ParticipantError, TOML, r"absent=\['lunate'\]"),
    (
        "no calibrate trial",
        'role = "calibrate"',
        'role = "other"',
        ParticipantError,
        TOML,
        "role \"calibrate\", but got .*'unresisted': 'other'",
    ),
    (
        "two calibrate trials",
        'role = "validate"',
        'role = "calibrate"',
        ParticipantError,
        TOML,
        "exactly one trial must have role \"calibrate\", but got .*'resisted': 'calibrate'",
    ),
    (
        "trial role",
        'role = "calibrate"',
        'role = "train"',
        ParticipantError,
        TOML,
        r"\[trials.unresisted\] role must be one of.*'train'",
    ),
    ("frames", "frames = 15", "frames = 12", TrialError, "trials/unresisted.csv", "n_frames=12 frames, but has 15"),
    (
        "ulnar variance",
        "age = 41",
        "age = 41\nulnar_variance_mm = 7.5",
        ParticipantError,
        TOML,
        r"ulnar_variance_mm must be a finite number in \[-5, 5\] \(mm, \+ ulna plus.*but got 7.5",
    ),
    (
        "ulnar variance nan",
        "age = 41",
        "age = 41\nulnar_variance_mm = nan",
        ParticipantError,
        TOML,
        r"ulnar_variance_mm must be a finite number.*but got nan",
    ),
    (
        "ulnar variance string",
        "age = 41",
        'age = 41\nulnar_variance_mm = "+1"',
        ParticipantError,
        TOML,
        r"ulnar_variance_mm must be a finite number.*but got '\+1'",
    ),
]
MISSING_FILES = [
    # (file removed, error, file named, message)
    (TOML, ParticipantError, TOML, "does not exist"),
    ("bones/lunate.stl", ParticipantError, TOML, "bones.lunate = 'bones/lunate.stl', but .*does not exist"),
    ("trials/resisted.csv", ParticipantError, TOML, "trials/resisted.csv', but .*does not exist"),
]


@pytest.mark.parametrize("case", BAD_TOML, ids=[c[0] for c in BAD_TOML])
def test_a_bad_participant_toml_names_the_file_and_the_value(folder, case):
    _, old, new, error, named, message = case
    edit_toml(folder, old, new)
    with raises(error, folder / named, message):
        load_participant_folder(folder)


@pytest.mark.parametrize("case", MISSING_FILES, ids=[c[0] for c in MISSING_FILES])
def test_a_missing_file_is_named(folder, case):
    removed, error, named, message = case
    (folder / removed).unlink()
    with raises(error, folder / named, message):
        load_participant_folder(folder)


def _outside(tmp_path):
    secret = tmp_path / "outside" / "secret.stl"
    secret.parent.mkdir()
    secret.write_text("SECRET-CONTENT")
    return secret


@pytest.mark.parametrize("how", ["dotdot", "absolute", "symlink", "proc"])
def test_listed_files_must_stay_inside_the_folder(folder, tmp_path, how):
    """A bone or trial path that leaves the folder (`..`, absolute, a link out, /proc) is refused
    before it is read: the message names participant.toml and never carries the file's content."""
    secret = _outside(tmp_path)
    entry = {
        "dotdot": "../outside/secret.stl",
        "absolute": str(secret),
        "symlink": "bones/link.stl",
        "proc": "../../../../../../../../proc/self/environ",
    }[how]
    if how == "symlink":
        (folder / "bones" / "link.stl").symlink_to(secret)
    key = '"trials/unresisted.csv"' if how == "proc" else '"bones/lunate.stl"'
    edit_toml(folder, key, '"' + entry + '"')
    with pytest.raises(ParticipantError) as err:
        load_participant_folder(folder)
    message = str(err.value)
    assert str(folder / "participant.toml") in message and ("outside" in message or "relative" in message), message
    assert "SECRET" not in message and "PATH=" not in message


def test_a_link_inside_the_folder_is_fine(folder):
    (folder / "bones" / "lunate.stl").rename(folder / "bones" / "real_lunate.stl")
    (folder / "bones" / "lunate.stl").symlink_to(folder / "bones" / "real_lunate.stl")
    assert "lunate" in load_participant_folder(folder).bones


def test_unreadable_mesh_file(folder):
    (folder / "bones" / "lunate.ply").write_bytes(b"\x00\x01 not a mesh\n")
    edit_toml(folder, '"bones/lunate.stl"', '"bones/lunate.ply"')
    with raises(MeshError, folder / "bones" / "lunate.ply", "trimesh cannot read the lunate mesh: ValueError"):
        load_participant_folder(folder)


def test_mesh_file_without_triangles(folder):
    (folder / "bones" / "lunate.stl").write_text("solid empty\nendsolid empty\n")
    with raises(MeshError, folder / "bones" / "lunate.stl", "must hold a triangle mesh.*faces.shape=\\(0, 3\\)"):
        load_participant_folder(folder)


def test_nan_vertices(folder):
    vertices, faces = bone_meshes()["lunate"]
    vertices = vertices.copy()
    vertices[5, 1] = np.nan
    replace_mesh(folder, "lunate", vertices, faces)
    with raises(MeshError, folder / "bones" / "lunate.stl", "vertices must be finite.*nan"):
        load_participant_folder(folder)


def test_mesh_in_metres(folder):
    vertices, faces = bone_meshes()["lunate"]
    replace_mesh(folder, "lunate", vertices / 1000, faces)
    diagonal = np.linalg.norm(np.ptp(vertices / 1000, axis=0))
    assert 0.02 < diagonal < 0.04
    with raises(
        MeshError,
        folder / "bones" / "lunate.stl",
        rf"looks like metres: bounding-box diagonal {diagonal:.3g}; convert to mm \(×1000\)",
    ):
        load_participant_folder(folder)


def test_carpal_mesh_too_large(folder):
    vertices, faces = bone_meshes()["capitate"]
    replace_mesh(folder, "capitate", vertices * 10, faces)
    with raises(
        MeshError, folder / "bones" / "capitate.stl", "looks like the wrong unit: bounding-box diagonal 3[0-9]{2}"
    ):
        load_participant_folder(folder)


def test_radius_mesh_too_large(folder):
    vertices, faces = bone_meshes()["radius"]
    replace_mesh(folder, "radius", vertices * 10, faces)
    with raises(MeshError, folder / "bones" / "radius.stl", "wrong unit: bounding-box diagonal 6[0-9]{2}.*10–600 mm"):
        load_participant_folder(folder)


def test_carpal_mesh_in_centimetres(folder):
    vertices, faces = bone_meshes()["scaphoid"]
    replace_mesh(folder, "scaphoid", vertices / 10, faces)
    with raises(
        MeshError, folder / "bones" / "scaphoid.stl", r"wrong unit: bounding-box diagonal 3\.[0-9]+, expected 5–100 mm"
    ):
        load_participant_folder(folder)


def test_non_watertight_mesh(folder):
    vertices, faces = bone_meshes()["lunate"]
    replace_mesh(folder, "lunate", vertices, faces[1:])
    with raises(MeshError, folder / "bones" / "lunate.stl", "watertight, but it has 3 boundary edges"):
        load_participant_folder(folder)


def test_zero_area_faces(folder):
    vertices, faces = bone_meshes()["lunate"]
    replace_mesh(folder, "lunate", vertices, np.vstack([faces, [[0, 0, 1], [2, 2, 3]]]))
    with raises(
        MeshError,
        folder / "bones" / "lunate.stl",
        r"has 2 degenerate faces \(zero area or slivers.*face 320 = \[(\d+), \1, \d+\], area 0 mm²",
    ):
        load_participant_folder(folder)


def test_duplicate_faces(folder):
    vertices, faces = bone_meshes()["lunate"]
    replace_mesh(folder, "lunate", vertices, np.vstack([faces, faces[[4]]]))
    with raises(MeshError, folder / "bones" / "lunate.stl", "has 1 duplicate faces.*face 320"):
        load_participant_folder(folder)


def test_inverted_winding(folder):
    vertices, faces = bone_meshes()["lunate"]
    volume = trimesh.Trimesh(vertices, faces).volume
    replace_mesh(folder, "lunate", vertices, faces[:, ::-1])
    with raises(MeshError, folder / "bones" / "lunate.stl", f"positive volume, but has -{volume:.4g} mm³"):
        load_participant_folder(folder)


def test_inconsistent_winding(folder):
    vertices, faces = bone_meshes()["lunate"]
    faces = faces.copy()
    faces[0] = faces[0, ::-1]
    replace_mesh(folder, "lunate", vertices, faces)
    with raises(MeshError, folder / "bones" / "lunate.stl", "consistently wound"):
        load_participant_folder(folder)


def test_too_few_faces(folder):
    mesh = trimesh.creation.icosphere(subdivisions=1)
    mesh.apply_scale(10.0)
    replace_mesh(folder, "lunate", mesh.vertices, mesh.faces)
    with raises(MeshError, folder / "bones" / "lunate.stl", "at least 100 faces, but has 80"):
        load_participant_folder(folder)


def test_bad_trial_csv_names_its_file(folder):
    path = folder / "trials" / "resisted.csv"
    path.write_text(path.read_text().replace(",lunate,", ",pisiform,", 1))  # no body of the model's
    with raises(TrialError, path, "line 5 has 'pisiform'"):
        load_participant_folder(folder)


# --- meshes that passed or got the wrong message before (issue 11): a table of bad folders ----------


def sliver_lunate():
    """The lunate with face 0 (a, b, c) split at the midpoint m of its edge ab, stored as float32 (as an
    STL is): faces (a, m, c), (m, b, c) and the sliver (a, b, m), last, of area ~2e-7 mm² — not zero,
    since rounding moves m off the line ab — and height ~2e-7 mm."""
    vertices, faces = bone_meshes()["lunate"]
    a, b, c = faces[0]
    vertices = np.vstack([vertices, (vertices[a] + vertices[b]) / 2]).astype(np.float32).astype(np.float64)
    m = len(vertices) - 1
    return vertices, np.vstack([faces[1:], [[a, m, c], [m, b, c], [a, b, m]]])


def flat_lunate():
    """The lunate turned and pressed into the plane z = −2: closed, wound consistently, no two vertices
    merged and no face of zero area, but of volume 0 (once blamed on inverted winding)."""
    vertices, faces = bone_meshes()["lunate"]
    centre = vertices.mean(axis=0)
    vertices = (vertices - centre) @ Rotation.from_euler("xy", [20, 35], degrees=True).as_matrix().T + centre
    vertices[:, 2] = -2.0
    return vertices, faces


def pillow_lunate(n: int = 12):
    """Two sheets on the curved surface z = (x² + y²) / 40 sharing their rim, the lower one's inner vertices
    1 µm below the upper's: closed and wound outward, not flat, but enclosing almost nothing."""
    xs = np.linspace(-10, 10, n)
    x, y = (a.ravel() for a in np.meshgrid(xs, xs, indexing="ij"))
    top = np.column_stack([x, y - 10, (x**2 + y**2) / 40])
    inner = (np.abs(x) < 10) & (np.abs(y) < 10)
    vertices = np.vstack([top, top[inner] - [0, 0, 1e-3]])
    lower = np.arange(n * n)
    lower[inner] = n * n + np.arange(inner.sum())
    i, j = (a.ravel() for a in np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="ij"))
    p00, p01, p10, p11 = ((i + di) * n + j + dj for di, dj in ((0, 0), (0, 1), (1, 0), (1, 1)))
    towards_centre = ((i < (n - 1) / 2) == (j < (n - 1) / 2))[:, None]  # so no face has three rim vertices
    cells = np.vstack(
        [
            np.where(towards_centre, np.column_stack([p00, p10, p11]), np.column_stack([p00, p10, p01])),
            np.where(towards_centre, np.column_stack([p00, p11, p01]), np.column_stack([p10, p11, p01])),
        ]
    )
    return vertices, np.vstack([cells, lower[cells][:, ::-1]])


def open_radius():
    """The radius capsule with one face removed: open, and no closed part left."""
    vertices, faces = bone_meshes()["radius"]
    return vertices, faces[1:]


def nan_lunate():
    vertices, faces = bone_meshes()["lunate"]
    vertices = vertices.copy()
    vertices[5, 1] = np.nan
    return vertices, faces


NAN_FACE = int(np.flatnonzero((bone_meshes()["lunate"][1] == 5).any(axis=1))[0])
NAN_CORNER = int(np.flatnonzero(bone_meshes()["lunate"][1][NAN_FACE] == 5)[0])

BAD_MESHES = {  # case: (bone, mesh, file suffix, message after the file name)
    "sliver": (
        "lunate",
        sliver_lunate,
        "stl",
        r"1 degenerate faces \(zero area or slivers: least height below 1e-06 × its diagonal = 2.8e-05 mm\) "
        r"\(first: face 321 = \[\d+, \d+, 162\], area [0-9.]+e-07 mm², height [0-9.]+e-07 mm\)",
    ),
    "flat": ("lunate", flat_lunate, "stl", "is flat: its vertices lie within 0 mm of one plane"),
    "no volume": (
        "lunate",
        pillow_lunate,
        "stl",
        r"encloses almost no volume: 0.3\d+ mm³ inside 86\d.\d mm² of surface \(a flat or folded sheet",
    ),
    "NaN, STL": (
        "lunate",
        nan_lunate,
        "stl",
        rf"5 triangle corners are not \(first: triangle {NAN_FACE}, corner "
        rf"{NAN_CORNER} = \[0.0, nan, [0-9.]+\]; indices 0-based, in file order\)",
    ),
    "NaN, OBJ": (
        "lunate",
        nan_lunate,
        "obj",
        r"1 vertices are not \(first: vertex 5 = \[0.0, nan, [0-9.]+\], used by "
        r"faces \[\d+, \d+, \d+\]; indices 0-based, in file order\)",
    ),
    "NaN, PLY": ("lunate", nan_lunate, "ply", r"1 vertices are not \(first: vertex 5 = \[0.0, nan, [0-9.]+\], used by"),
    "open radius": (
        "radius",
        open_radius,
        "stl",
        r"the radius mesh must have a closed \(watertight\) part, its "
        r"articular solid.*spans 0 mm \(it has 3 boundary edges",
    ),
}


@pytest.mark.parametrize("case", BAD_MESHES)
def test_bad_mesh_gets_a_clear_error(folder, case):
    """Each bad mesh is refused with a MeshError naming its file, what is wrong and the value."""
    bone, make, suffix, message = BAD_MESHES[case]
    replace_mesh(folder, bone, *make(), name=f"{bone}.{suffix}")
    with raises(MeshError, folder / "bones" / f"{bone}.{suffix}", message):
        load_participant_folder(folder)


def test_a_sliver_is_not_zero_area(folder):
    """The sliver above passed the old zero-area rule (area <= 1e-12 × diagonal²), and is refused now."""
    vertices, faces = sliver_lunate()
    area = trimesh.Trimesh(vertices, faces, process=False).area_faces[-1]
    assert 1e-12 * np.linalg.norm(np.ptp(vertices, axis=0)) ** 2 < area < 1e-6


def _never_read(monkeypatch, path) -> None:
    """Fail the test if trimesh is asked to read `path` (other files are read as usual)."""
    load = trimesh.load_mesh
    monkeypatch.setattr(
        folder_module.trimesh,
        "load_mesh",
        lambda file, **kw: pytest.fail("read") if Path(file) == path else load(file, **kw),
    )


@pytest.mark.parametrize("suffix", ["stl", "ascii.stl", "obj", "ply", "off"])
def test_a_mesh_with_too_many_faces_is_refused(folder, monkeypatch, suffix):
    """Above `MAX_FACES` (here lowered to 1,000 for a carpal, and the lunate subdivided to 1,280 faces) a
    mesh is refused with the limit; STL, OBJ and PLY before trimesh reads them (headers or lines give the count)."""
    monkeypatch.setitem(folder_module.MAX_FACES, "carpal", 1000)
    vertices, faces = trimesh.remesh.subdivide(*bone_meshes()["lunate"])
    path = folder / "bones" / f"lunate.{suffix}"
    if suffix == "ascii.stl":
        path.write_text(trimesh.exchange.stl.export_stl_ascii(trimesh.Trimesh(vertices, faces)))
        edit_toml(folder, '"bones/lunate.stl"', f'"bones/lunate.{suffix}"')
    else:
        replace_mesh(folder, "lunate", vertices, faces, name=f"lunate.{suffix}")
    if suffix != "off":  # trimesh must not be asked to read it
        _never_read(monkeypatch, path)
    with raises(
        MeshError,
        path,
        r"the lunate mesh has 1,280 faces, more than the 1,000 a carpal mesh may have.*"
        r"decimate it to at most 1,000 faces",
    ):
        load_participant_folder(folder)


def test_face_limits_leave_room_above_the_builtin_meshes():
    """The built-in meshes have at most a tenth of the limit (radius 18,224 faces, carpals <= 4,746)."""
    source = builtin.source("P1")
    for bone, (_, faces) in source.bones.items():
        limit = folder_module.MAX_FACES["carpal" if bone in folder_module.CARPALS else "forearm"]
        assert len(faces) <= limit / 10, bone


def test_an_open_ulna_is_accepted_without_solid(folder):
    """An ulna may be open (ligament sites only), as the built-in ones are; it then has no solid part."""
    vertices, faces = bone_meshes()["ulna"]
    replace_mesh(folder, "ulna", vertices, faces[1:])
    loaded = load_participant_folder(folder)
    assert not folder_module.solid_mask(*loaded.bones["ulna"]).any()
    assert folder_module.solid_mask(*loaded.bones["radius"]).all()


def test_a_builtin_participant_round_trips_through_a_folder(tmp_path):
    """Built-in P1 written as a folder loads back (its radius keeps the open shaft beside the closed
    articular solid, its ulna is closed at the cut for the TFCC), and the registry gives the build the
    same bones (those a folder supplies: the radial column comes with the capitate): triangles to
    float32 precision, the same solid (contact and mass) faces."""
    source = dataclasses.replace(builtin.source("P1"), name="P1_copy")
    loaded = load_participant_folder(write_participant_folder(source, tmp_path / "p1_copy"))
    assert loaded.meta == source.meta
    for bone in SUPPLIED:
        assert_same_triangles(loaded.bones[bone], source.bones[bone], atol=1e-5)
    for name, trial in source.trials.items():
        np.testing.assert_allclose(loaded.trials[name].transforms, trial.transforms, atol=1e-12)
    registry.add_folder(tmp_path / "p1_copy")
    copy = registry.bones("P1_copy", BuildParams(distal_row=False))
    original = builtin.bones("P1", BuildParams().fossa_sweep_deg, False)
    for bone in SUPPLIED:
        np.testing.assert_array_equal(copy[bone].solid[copy[bone].faces], original[bone].solid[original[bone].faces])
    assert copy["ulna"].solid.all() and 0 < copy["radius"].solid.sum() < len(copy["radius"].solid)


@pytest.mark.parametrize(
    "data, message",
    [
        (b"garbage " * 40, r"not an STL file: neither binary \(its header declares .* faces.*nor ASCII"),
        (b"\0" * 80 + (0xFFFFFFF0).to_bytes(4, "little") + b"\0" * 100, r"declares 4,294,967,280 faces.*has 184"),
        (b"short", r"not an STL file: 5 bytes, shorter than a binary STL's 84-byte header"),
    ],
    ids=["garbage", "header claims 0xFFFFFFF0 faces", "shorter than a header"],
)
def test_a_file_that_is_no_stl_is_called_that_before_trimesh_reads_it(folder, monkeypatch, data, message):
    path = folder / "bones" / "lunate.stl"
    path.write_bytes(data)
    _never_read(monkeypatch, path)
    with raises(MeshError, path, message):
        load_participant_folder(folder)


def test_a_padded_binary_stl_over_the_face_limit_is_refused_by_its_header(folder, monkeypatch):
    monkeypatch.setitem(folder_module.MAX_FACES, "carpal", 1000)
    replace_mesh(folder, "lunate", *trimesh.remesh.subdivide(*bone_meshes()["lunate"]))
    path = folder / "bones" / "lunate.stl"
    path.write_bytes(path.read_bytes() + b"\0" * 64)  # bytes past the 1,280 faces its header declares
    _never_read(monkeypatch, path)
    with raises(MeshError, path, "1,280 faces, more than the 1,000 a carpal mesh may have"):
        load_participant_folder(folder)


@pytest.mark.parametrize("kind", ["folder", "fifo"])
def test_a_bone_path_that_is_no_regular_file_is_called_that(folder, kind):
    path = folder / "bones" / "lunate.stl"
    path.unlink()
    path.mkdir() if kind == "folder" else os.mkfifo(path)
    with raises(ParticipantError, folder / TOML, "is a folder" if kind == "folder" else "is not a regular file"):
        load_participant_folder(folder)


def test_a_byte_order_mark_in_participant_toml_is_dropped(folder):
    path = folder / TOML
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    assert load_participant_folder(folder).name == "P7"


def test_two_folders_with_one_name_are_refused(folder, tmp_path, monkeypatch):
    import shutil

    from wrist_env.participants import registry

    monkeypatch.setattr(registry, "_FOLDERS", {})
    monkeypatch.setattr(registry, "_SOURCES", {})
    other = tmp_path / "other_wrist"
    shutil.copytree(folder, other)
    assert registry.add_folder(folder) == "P7" and registry.add_folder(folder) == "P7"  # the same folder again
    with raises(ParticipantError, other / TOML, f"name 'P7' is taken by the folder {folder}"):
        registry.add_folder(other)


@pytest.mark.parametrize(
    "first, second, value",
    [("scaphoid", "lunate", "ulnar of the lunate"), ("lunate", "capitate", "proximal of the lunate")],
)
def test_swapped_bones_are_named_before_the_build(folder, first, second, value):
    """Two carpal files listed under each other's names: refused when the folder is read, naming both
    entries (not, after a build, as implausible joint spaces with a hint about `side`)."""
    edit_toml(folder, f'{first} = "bones/{first}.stl"', f'{first} = "bones/SWAP.stl"')
    edit_toml(folder, f'{second} = "bones/{second}.stl"', f'{second} = "bones/{first}.stl"')
    edit_toml(folder, f'{first} = "bones/SWAP.stl"', f'{first} = "bones/{second}.stl"')
    with raises(ParticipantError, folder / "participant.toml", f"look swapped.*{value}"):
        load_participant_folder(folder)


# --- issue 54: a folder may give its own triquetrum, trapezium, trapezoid and hamate -------

HAMATE = (7.0, 11.0, 6.0)
"""An ellipsoid hamate's semi-axes (mm): placed ulnar of `CARPALS`' capitate, touching it."""


def add_bone(folder, bone: str, centre) -> None:
    """An ellipsoid `HAMATE`-sized mesh at `centre` (mm), listed in [bones] after the capitate."""
    mesh = trimesh.creation.icosphere(subdivisions=2)
    mesh.apply_scale(HAMATE)
    mesh.apply_translation(centre)
    mesh.export(folder / "bones" / f"{bone}.stl")
    edit_toml(
        folder, 'capitate = "bones/capitate.stl"', f'capitate = "bones/capitate.stl"\n{bone} = "bones/{bone}.stl"'
    )


def test_a_folder_may_give_its_own_hamate(tmp_path, folder):
    add_bone(folder, "hamate", (0.0, -28.0, -10.0))
    loaded = load_participant_folder(folder)
    assert tuple(loaded.bones) == SUPPLIED + ("hamate",)
    again = load_participant_folder(write_participant_folder(loaded, tmp_path / "again"))
    assert tuple(again.bones) == tuple(loaded.bones)
    assert_same_triangles(again.bones["hamate"], loaded.bones["hamate"], atol=1e-5)


@pytest.mark.parametrize(
    "centre, value",
    [
        ((0.0, -28.0, -40.0), r"bones.hamate \(hamate.stl\) comes no nearer than 30.0 mm to the capitate"),
        ((0.0, -28.0, 16.0), r"bones.hamate \(hamate.stl\) has its centroid 13.0 mm radial of the capitate's"),
    ],
    ids=["far", "wrong side"],
)
def test_a_given_bone_out_of_place_is_named(folder, centre, value):
    """A given bone in another frame or unit, or on the wrong side of the bone it articulates with, is
    refused when the folder is read, naming the entry and its file."""
    add_bone(folder, "hamate", centre)
    with raises(ParticipantError, folder / "participant.toml", value):
        load_participant_folder(folder)


def test_a_bone_the_model_has_no_place_for_is_refused(folder):
    add_bone(folder, "pisiform", (0.0, -28.0, -10.0))
    with raises(ParticipantError, folder / "participant.toml", r"may list any of \('triquetrum'.*extra=\['pisiform'\]"):
        load_participant_folder(folder)


# --- issue 53: islands, one file for two bones, paths -------------------------------------


def scaphoid_with_island(radius_mm: float = 1.0, offset_mm: float = 40.0):
    """The scaphoid and a sphere of `radius_mm` (80 faces after one subdivision, 320 after two)
    `offset_mm` away from its centre along x: two closed pieces, each wound outward."""
    vertices, faces = bone_meshes()["scaphoid"]
    island = trimesh.creation.icosphere(subdivisions=1, radius=radius_mm)
    island.apply_translation(np.array(CARPALS["scaphoid"][1], float) + [offset_mm, 0.0, 0.0])
    return np.vstack([vertices, island.vertices]), np.vstack([faces, island.faces + len(vertices)])


def test_a_carpal_with_a_detached_piece_is_refused_naming_the_pieces(folder):
    """A scaphoid with a 2 mm sphere 40 mm away (closed, outward, so every other rule passes) is refused
    when the folder is read, naming the file and each piece's faces and extent (bounding-box diagonal:
    the sphere's 2√3 mm)."""
    replace_mesh(folder, "scaphoid", *scaphoid_with_island())
    with raises(
        MeshError,
        folder / "bones" / "scaphoid.stl",
        r"one connected piece, but it has 2: 320 faces over 30.\d mm; 80 faces over 3.4\d mm.*drop_islands = true",
    ):
        load_participant_folder(folder)


def test_pieces_touching_at_a_vertex_are_two(folder):
    """Pieces are connected through shared edges: two spheres sharing one vertex are two pieces."""
    a = trimesh.creation.icosphere(subdivisions=2, radius=5.0)
    top = int(np.argmax(a.vertices[:, 0]))
    b = a.copy()
    b.apply_translation([2 * a.vertices[top, 0], 0.0, 0.0])  # its lowest-x vertex onto a's highest-x one
    merged = trimesh.util.concatenate([a, b])
    merged.merge_vertices()
    assert len(merged.vertices) == len(a.vertices) + len(b.vertices) - 1
    assert len(folder_module.pieces(merged.vertices, merged.faces)) == 2


def test_drop_islands_keeps_the_largest_piece(folder):
    """With drop_islands = true the scaphoid's largest piece is kept, with a warning naming the file and
    the dropped piece; the other bones are as before."""
    vertices, faces = bone_meshes()["scaphoid"]
    replace_mesh(folder, "scaphoid", *scaphoid_with_island())
    edit_toml(folder, 'units = "mm"', 'units = "mm"\ndrop_islands = true')
    with pytest.warns(UserWarning, match=rf"{re.escape(str(folder / 'bones' / 'scaphoid.stl'))}.*dropped 1 \(80 faces"):
        loaded = load_participant_folder(folder)
    assert loaded.meta["drop_islands"] is True
    assert_same_triangles(loaded.bones["scaphoid"], (vertices, faces), atol=1e-5)


def test_drop_islands_does_not_drop_half_a_bone(folder):
    """A second piece of more than `ISLAND_AREA_SHARE` of the largest's area (here a sphere of 6 mm radius,
    ~50 %) is two parts of a bone, not an island: refused even with drop_islands."""
    replace_mesh(folder, "scaphoid", *scaphoid_with_island(radius_mm=6.0))
    edit_toml(folder, 'units = "mm"', 'units = "mm"\ndrop_islands = true')
    with raises(MeshError, folder / "bones" / "scaphoid.stl", r"2 pieces, and the second has \d+% .*not an island"):
        load_participant_folder(folder)


def test_drop_islands_must_be_a_boolean(folder):
    edit_toml(folder, 'units = "mm"', 'units = "mm"\ndrop_islands = "yes"')
    with raises(ParticipantError, folder / TOML, "drop_islands must be true or false, but got 'yes'"):
        load_participant_folder(folder)


@pytest.mark.parametrize("name", list(builtin.BUILTIN) + ["template"])
def test_builtin_and_template_carpals_are_one_piece(name):
    """The shipped meshes pass the rule (the radius is several pieces, articular solid and shaft, and is
    not checked); the template's principal bones are those the folders' are carried from."""
    from wrist_env.anatomy.template import load_template

    meshes = (
        {b: (s.vertices, s.faces) for b, s in load_template().bones.items() if b in SUPPLIED}
        if name == "template"
        else builtin.source(name).bones
    )
    for bone, (vertices, faces) in meshes.items():
        folder_module.validate_bone_mesh(np.asarray(vertices), np.asarray(faces), bone, f"{name} {bone}")
        if bone in folder_module.CARPALS:
            assert len(folder_module.pieces(vertices, faces)) == 1, bone


@pytest.mark.parametrize("how", ["same path", "same path through a link", "identical copy"])
def test_two_bones_with_one_file_are_refused_at_load(folder, monkeypatch, how):
    """Two bones listed with one file are refused before any mesh is read, naming both bones and the file
    (not, after a build of minutes, as implausible joint spaces)."""
    lunate = folder / "bones" / "lunate.stl"
    if how == "same path":
        edit_toml(folder, 'lunate = "bones/lunate.stl"', 'lunate = "bones/scaphoid.stl"')
        value = (
            rf"bones.scaphoid and bones.lunate are the same file {re.escape(str(folder / 'bones' / 'scaphoid.stl'))}"
        )
    elif how == "same path through a link":
        lunate.unlink()
        lunate.symlink_to(folder / "bones" / "scaphoid.stl")
        value = "bones.scaphoid and bones.lunate are the same file"
    else:
        lunate.write_bytes((folder / "bones" / "scaphoid.stl").read_bytes())
        value = r"bones.scaphoid and bones.lunate are files of identical content \(.*scaphoid.stl and .*lunate.stl\)"
    monkeypatch.setattr(folder_module.trimesh, "load_mesh", lambda *a, **k: pytest.fail("a mesh was read"))
    with raises(ParticipantError, folder / TOML, value):
        load_participant_folder(folder)


def _loop(tmp_path) -> Path:
    (tmp_path / "loop_a").symlink_to(tmp_path / "loop_b")
    (tmp_path / "loop_b").symlink_to(tmp_path / "loop_a")
    return tmp_path / "loop_a"


@pytest.mark.parametrize("how", ["null byte", "symlink loop", "under a symlink loop"])
@pytest.mark.parametrize("enter", ["load_participant_folder", "add_folder", "ensure_folder"])
def test_a_folder_path_with_a_null_byte_or_a_loop_is_one_line(tmp_path, how, enter):
    """Wherever a folder path enters, a null byte or a symlink loop is a ParticipantError naming the path
    (a null byte shown escaped), not a ValueError or RuntimeError traceback."""
    if how == "null byte":
        path, shown = str(tmp_path / "my\0wrist"), repr(str(tmp_path / "my\0wrist"))
    else:
        path = _loop(tmp_path) if how == "symlink loop" else _loop(tmp_path) / "my_wrist"
        shown = str(path)
    call = load_participant_folder if enter == "load_participant_folder" else getattr(registry, enter)
    with pytest.raises(ParticipantError, match=re.escape(shown)):
        call(path)


@pytest.mark.parametrize("how", ["null byte", "symlink loop"])
def test_a_listed_file_with_a_null_byte_or_a_loop_is_one_line(folder, how):
    if how == "symlink loop":
        (folder / "bones" / "lunate.stl").unlink()
        _loop(folder / "bones")
        edit_toml(folder, '"bones/lunate.stl"', '"bones/loop_a"')
        value = "bones.lunate = 'bones/loop_a' cannot be resolved"
    else:
        edit_toml(folder, '"bones/lunate.stl"', '"bones/lunate\\u0000.stl"')
        value = r"bones.lunate = 'bones/lunate\\x00.stl' cannot be resolved"
    with raises(ParticipantError, folder / TOML, value):
        load_participant_folder(folder)


def test_frames_in_participant_toml_are_bounded(folder):
    edit_toml(folder, "frames = 15", "frames = 1000000000000")
    with raises(ParticipantError, folder / TOML, r"frames must be an integer in \[2, 1,000\].*1000000000000"):
        load_participant_folder(folder)


def test_a_stated_ulnar_variance_is_the_builds_unless_the_parameters_give_one(folder):
    """participant.toml's `ulnar_variance_mm` reaches `BuildParams` (`registry.build_params`, which
    `load_model` builds with); a variance in the parameters wins; it round-trips through a folder. A
    built-in is seated at `builtin.ULNAR_VARIANCE_MM`."""
    edit_toml(folder, "age = 41", "age = 41\nulnar_variance_mm = 1")
    assert load_participant_folder(folder).meta["ulnar_variance_mm"] == 1.0
    name = registry.add_folder(folder)
    assert registry.build_params(name).ulnar_variance_mm == 1.0
    assert registry.build_params(name, BuildParams(distal_row=False)) == BuildParams(
        distal_row=False, ulnar_variance_mm=1.0
    )
    assert registry.build_params(name, BuildParams(ulnar_variance_mm=-2)).ulnar_variance_mm == -2.0
    copy = write_participant_folder(load_participant_folder(folder), folder.parent / "copy")
    assert load_participant_folder(copy).meta["ulnar_variance_mm"] == 1.0
    assert registry.build_params("P1") == BuildParams(ulnar_variance_mm=0.26)  # the built-ins' seat (Yoshioka 2007)
