"""Read the carpal anatomy that ships in the `myo-sim` package.

Meshes come from `myo_sim/models/meshes/*.stl` (metres, each in its own body
frame); the neutral assembly comes from the bodies' `pos`/`quat` in
`myo_sim/models/arm/assets/myoarm_r_chain.xml` (lunate in radius, scaphoid
and capitate in lunate, radius in ulna). Everything returned here is in the
myo-sim *radius body frame*, in millimetres; `wrist_env.anatomy.frames` turns
it into the radius coordinate system (RCS).
"""

from __future__ import annotations

import importlib.resources
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np
import trimesh

from wrist_env.errors import BuildError
from wrist_env.model import PARTS

CHAIN_XML = "models/arm/assets/myoarm_r_chain.xml"
MESH_DIR = "models/meshes"

# Tendon paths that cross the wrist, read from the MJCF (sites and wrapping
# geoms of the lunate and capitate bodies): their mean positions give the
# volar (flexor) and dorsal (extensor) sides of the wrist.
FLEXOR_PREFIXES = ("FDS", "FDP", "FCR", "PL", "WristFlexor")
EXTENSOR_PREFIXES = ("EDC", "ECRL", "ECRB", "WristExtensor")


@dataclass(frozen=True)
class MyoSimAnatomy:
    """Bone meshes in the myo-sim radius body frame (mm) and tendon landmarks.

    meshes: bone name -> trimesh.Trimesh, vertices in mm.
    flexor_sites, extensor_sites: arrays of shape (k, 3), mm.
    """

    meshes: dict
    flexor_sites: np.ndarray
    extensor_sites: np.ndarray


def _vec(text: str | None, default=(0.0, 0.0, 0.0)) -> np.ndarray:
    return np.array([float(v) for v in text.split()]) if text else np.array(default, float)


def _body_transform(body: ET.Element) -> np.ndarray:
    """4x4 transform of a body in its parent (metres), from `pos` and `quat` (w x y z)."""
    T = np.eye(4)
    T[:3, 3] = _vec(body.get("pos"))
    if body.get("quat"):
        w, x, y, z = _vec(body.get("quat"))
        T[:3, :3] = trimesh.transformations.quaternion_matrix([w, x, y, z])[:3, :3]
    if body.get("euler"):
        raise BuildError(f"body {body.get('name')!r} uses `euler`, which this reader does not handle")
    return T


def radius_frame_transforms(root: ET.Element) -> dict:
    """Every body of a myo-sim chain (`root`: its parsed XML) in the radius body's frame: body name ->
    4×4 (m), the body's frame composed up its parents to the world, then into `radius_r`'s."""
    bodies = {b.get("name"): b for b in root.iter("body")}
    parent = {c.get("name"): b.get("name") for b in root.iter("body") for c in b.findall("body")}

    def to_world(name: str) -> np.ndarray:
        T = np.eye(4)
        while name in bodies:
            T = _body_transform(bodies[name]) @ T
            name = parent.get(name)
        return T

    radius_inv = np.linalg.inv(to_world("radius_r"))
    return {name: radius_inv @ to_world(name) for name in bodies}


def _chain_transforms(root: ET.Element) -> tuple[dict, dict]:
    """World-free transforms of each needed body in the radius body frame, and body elements."""
    bodies = {b.get("name"): b for b in root.iter("body")}
    missing = [n for n in PARTS if f"{n}_r" not in bodies]
    if missing:
        raise BuildError(f"myo-sim chain {CHAIN_XML} lacks bodies {missing}")
    in_radius = radius_frame_transforms(root)
    return {n: in_radius[f"{n}_r"] for n in PARTS}, bodies


def _sites(bodies: dict, body_T: dict, prefixes: tuple[str, ...]) -> np.ndarray:
    points = []
    for bone in ("lunate", "capitate"):
        T = body_T[bone]
        for el in list(bodies[f"{bone}_r"].findall("site")) + list(bodies[f"{bone}_r"].findall("geom")):
            name = el.get("name") or ""
            if name.startswith(prefixes) and el.get("pos"):
                points.append((T @ np.append(_vec(el.get("pos")), 1.0))[:3])
    return np.asarray(points) * 1000.0


def load_myosim_anatomy() -> MyoSimAnatomy:
    """The nine bones (`model.PARTS`) assembled in their neutral pose, in mm, myo-sim radius frame."""
    pkg = importlib.resources.files("myo_sim")
    root = ET.parse(str(pkg / CHAIN_XML)).getroot()
    body_T, bodies = _chain_transforms(root)
    meshes = {}
    for bone in PARTS:
        path = pkg / MESH_DIR / f"{bone}.stl"
        mesh = trimesh.load(str(path), force="mesh", process=True)
        mesh.apply_transform(body_T[bone])
        mesh.apply_scale(1000.0)
        meshes[bone] = mesh
    flexor = _sites(bodies, body_T, FLEXOR_PREFIXES)
    extensor = _sites(bodies, body_T, EXTENSOR_PREFIXES)
    if len(flexor) == 0 or len(extensor) == 0:
        raise BuildError(f"no flexor/extensor landmarks found in {CHAIN_XML}")
    return MyoSimAnatomy(meshes=meshes, flexor_sites=flexor, extensor_sites=extensor)
