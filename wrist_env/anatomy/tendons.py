"""The wrist's tendon loads where they enter the carpus, from myo-sim's tendon paths (issue 33).

Paths: `myo_sim/models/arm/assets/myoarm_r_tendon.xml` (each tendon's ordered sites); sites:
`myoarm_r_chain.xml` (site `pos` in its body, bodies chained by `pos`/`quat`). Everything is in the
template's RCS (mm; x volar, y proximal, z radial) at the neutral pose; sites on the distal row and
the metacarpals move with the template's seated distal row (`midcarpal.read_seat`).

Per tendon:
- `site`: its first path site distal of the radius and ulna, where its free span across the wrist
  meets the hand (the insertion for FCR, ECRL, ECRB, ECU, APL; the pisiform for FCU; for the finger
  flexors, FPL and EPB a myo-sim pulley site on the capitate body: the carpal tunnel / first
  compartment). `point` is that site, `direction` the unit vector from it to the path's previous
  site (its last on the radius or ulna): the pull. With each ray rigid with its carpal this is the
  tendon's whole load on the hand. myo-sim's wrapping geoms are not followed: at neutral they bend
  FCR, ECRL, ECRB (round tori on the lunate body) and ECU (on the radius) by 6-13 degrees.
- `insertion_site`: its first site on the bone it loads (`LOADED_BONE`), which fixes `carpal`:
  1st metacarpal -> trapezium, 2nd -> trapezoid, 3rd -> capitate, 4th-5th -> hamate, pisiform ->
  hamate (the pisiform is a sesamoid in the FCU, whose tendon is "thence prolonged to the hamate and
  fifth metacarpal bone by pisohamate and pisometacarpal ligaments": Standring 2005, Gray's Anatomy,
  39th ed.); a finger flexor loads its ray's metacarpal.

Tensions: Erhart et al. 2020 (J Orthop Surg Res 15, doi:10.1186/s13018-020-01897-y, Table 1): a
rig that loads every wrist motor and the thumb and finger flexors with weights, holding the hand in
a grasp at neutral, which is the pose here. `Tendons.scaled` scales them so their *sum* is a stated
total: the rig states its load as tendon weights, and the sum does not change with the geometry
(the resultant's proximal component is 95-96 % of it).
"""

from __future__ import annotations

import functools
import importlib.resources
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from wrist_env.anatomy.midcarpal import read_seat
from wrist_env.anatomy.myosim import CHAIN_XML, radius_frame_transforms
from wrist_env.anatomy.template import load_template
from wrist_env.errors import BuildError
from wrist_env.model import BODY_PARTS, BONES

TENDON_XML = "models/arm/assets/myoarm_r_tendon.xml"
FOREARM_BODIES = ("humerus_r", "ulna_r", "radius_r")
DISTAL_ROW_BODIES = ("capitate_r", "trapezium_r", "trapezoid_r", "hamate_r") + tuple(
    f"{n}mc_r" for n in ("first", "second", "third", "fourth", "fifth")
)  # moved with the template's seated distal row; the pisiform stays with the proximal row
CARPAL_OF = {
    "firstmc_r": "trapezium",
    "secondmc_r": "trapezoid",
    "thirdmc_r": "capitate",
    "fourthmc_r": "hamate",
    "fifthmc_r": "hamate",
    "pisiform_r": "hamate",
}
RAY_MC = {2: "secondmc_r", 3: "thirdmc_r", 4: "fourthmc_r", 5: "fifthmc_r"}
LOADED_BONE = {
    "FCR": "secondmc_r",
    "FCU": "pisiform_r",
    "ECRL": "secondmc_r",
    "ECRB": "thirdmc_r",
    "ECU": "fifthmc_r",
    "APL": "firstmc_r",
    "EPB": "firstmc_r",
    "FPL": "firstmc_r",
} | {f"{m}{k}": RAY_MC[k] for m in ("FDS", "FDP") for k in (2, 3, 4, 5)}
"""The bone each included tendon loads (myo-sim body). EDC, EPL, PL are not loaded in Erhart's rig."""

FINGER_FLEXORS = tuple(f"{m}{k}" for m in ("FDS", "FDP") for k in (2, 3, 4, 5))
ERHART_2020 = {"FCR": 10.0, "FCU": 10.0, "ECU": 10.0, "ECRL": 10.0, "ECRB": 10.0, "APL": 5.0, "EPB": 5.0}
ERHART_2020 |= {"FPL": 5.0} | {t: 5.0 for t in FINGER_FLEXORS}
"""Erhart 2020 Table 1 (N) as issue 33 reads it: FCR, FCU, ECU 10; ECRL + ECRB 20 and APL + EPB 10,
each weight shared by its two tendons; FPL 5; 5 on each of the eight FDS/FDP tendons (105 N). The
default: the table gives one weight per row of 1, 2 or 8 tendons and does not say per tendon or per
group, so the issue's reading is kept and the other one offered."""
ERHART_2020_GROUPS = {t: v for t, v in ERHART_2020.items() if t not in FINGER_FLEXORS}
ERHART_2020_GROUPS |= {t: 5.0 / 8 for t in FINGER_FLEXORS}
"""The other reading of the same table (seven weights, one per tendon group): the eight FDS/FDP
tendons share one 5 N weight (70 N)."""
RIGS = {"erhart2020": ERHART_2020, "erhart2020_groups": ERHART_2020_GROUPS}


@dataclass(frozen=True)
class Tendons:
    """The tendons' loads at neutral, RCS. names, site, previous_site, insertion_site, bone, carpal:
    tuples (n,) of str; point (n, 3) mm; direction (n, 3) unit pull; tension (n,) N, the rig's."""

    names: tuple
    site: tuple
    previous_site: tuple
    insertion_site: tuple
    bone: tuple
    carpal: tuple
    point: np.ndarray
    direction: np.ndarray
    tension: np.ndarray

    def scaled(self, total_n: float) -> np.ndarray:
        """Tensions (n,) N, the rig's scaled so that they sum to `total_n`."""
        return self.tension * (float(total_n) / self.tension.sum())


@dataclass(frozen=True)
class CarpalLoad:
    """The resultant of the tendons on one carpal (or on all, carpal "all"), RCS: force (3,) N;
    moment (3,) N·mm about `about` (3,) mm; point (3,) mm, the central axis' point nearest `about`."""

    carpal: str
    force: np.ndarray
    moment: np.ndarray
    about: np.ndarray
    point: np.ndarray


def _parse(path) -> ET.Element:
    try:
        return ET.parse(str(path)).getroot()
    except (OSError, ET.ParseError) as exc:
        raise BuildError(f"cannot read myo-sim XML {path}: {exc}") from exc


def _sites_in_radius_frame(root: ET.Element) -> dict:
    """site name -> (body name, position (3,) m in the myo-sim radius body frame)."""
    in_radius = radius_frame_transforms(root)
    sites = {}
    for name, body in ((b.get("name"), b) for b in root.iter("body")):
        T = in_radius[name]
        for s in body.findall("site"):
            pos = np.array([float(v) for v in (s.get("pos") or "0 0 0").split()])
            sites[s.get("name")] = (name, (T @ np.append(pos, 1.0))[:3])
    return sites


def _to_rcs(body: str, p_m: np.ndarray, rcs_from_myosim: np.ndarray, seat: np.ndarray) -> np.ndarray:
    """A myo-sim radius-frame point (m) in the RCS (mm), seated with the distal row if it is on it."""
    q = rcs_from_myosim[:3, :3] @ (p_m * 1000.0)
    if body in DISTAL_ROW_BODIES:
        q = seat[:3, :3] @ q + seat[:3, 3]
    return q + rcs_from_myosim[:3, 3]


def load_tendons(rig: str | dict = "erhart2020", chain_xml=None, tendon_xml=None) -> Tendons:
    """The tendons of `rig` (a `RIGS` name or tendon -> N) at neutral, RCS (see module).

    chain_xml, tendon_xml: paths of myo-sim's XMLs (default: the installed package's)."""

    tensions = RIGS[rig] if isinstance(rig, str) else dict(rig)
    unknown = sorted(set(tensions) - set(LOADED_BONE))
    if unknown:
        raise BuildError(f"no loaded bone known for tendons {unknown} (LOADED_BONE)")
    pkg = importlib.resources.files("myo_sim")
    chain_path = Path(chain_xml) if chain_xml is not None else pkg / CHAIN_XML
    tendon_path = Path(tendon_xml) if tendon_xml is not None else pkg / TENDON_XML
    sites = _sites_in_radius_frame(_parse(chain_path))
    if "radius_r" not in {b for b, _ in sites.values()}:
        raise BuildError(f"myo-sim chain {chain_path} has no sites on body 'radius_r'")
    paths = {sp.get("name"): [s.get("site") for s in sp.findall("site")] for sp in _parse(tendon_path).iter("spatial")}
    template = load_template()
    seat = read_seat()
    rows = []
    for name, tension in tensions.items():
        path = paths.get(f"{name}_tendon")
        if path is None:
            raise BuildError(f"myo-sim tendons {tendon_path} lack spatial tendon '{name}_tendon'")
        missing = [s for s in path if s not in sites]
        if missing:
            raise BuildError(f"myo-sim chain {chain_path} lacks site {missing[0]!r} of tendon {name} ({tendon_path})")
        bodies = [sites[s][0] for s in path]
        k = next((i for i, b in enumerate(bodies) if b not in FOREARM_BODIES), None)
        if k is None or k == 0:
            raise BuildError(f"tendon {name} in {tendon_path} does not run from the forearm onto the hand")
        if LOADED_BONE[name] not in bodies[k:]:
            raise BuildError(f"tendon {name} in {tendon_path} has no site on {LOADED_BONE[name]}")
        insertion = path[bodies.index(LOADED_BONE[name])]
        point = _to_rcs(bodies[k], sites[path[k]][1], template.rcs_from_myosim, seat)
        previous = _to_rcs(bodies[k - 1], sites[path[k - 1]][1], template.rcs_from_myosim, seat)
        d = previous - point
        rows.append(
            (
                name,
                path[k],
                path[k - 1],
                insertion,
                bodies[k],
                CARPAL_OF[LOADED_BONE[name]],
                point,
                d / np.linalg.norm(d),
                tension,
            )
        )
    cols = list(zip(*rows))
    arrays = [np.array(cols[i], dtype=np.float64) for i in (6, 7, 8)]
    for a in arrays:
        a.setflags(write=False)
    return Tendons(*(tuple(c) for c in cols[:6]), *arrays)


def carpal_loads(tendons: Tendons, total_n: float, about=None) -> dict:
    """Per-carpal resultants (carpal -> `CarpalLoad`, plus "all") of the rig scaled to `total_n` (N,
    the tensions' sum); moments about `about` (3,) mm (default: the RCS origin)."""
    about = np.zeros(3) if about is None else np.asarray(about, dtype=np.float64)
    forces = tendons.direction * tendons.scaled(total_n)[:, None]
    moments = np.cross(tendons.point - about, forces)
    out = {}
    for carpal in sorted(set(tendons.carpal)) + ["all"]:
        mask = np.ones(len(forces), bool) if carpal == "all" else np.array([c == carpal for c in tendons.carpal])
        F, M = forces[mask].sum(axis=0), moments[mask].sum(axis=0)
        point = about + np.cross(F, M) / max(F @ F, 1e-300)
        out[carpal] = CarpalLoad(carpal, F, M, about.copy(), point)
    return out


_LINES: dict = {}


def carry_point(model, carpal: str, site: np.ndarray) -> tuple[int, np.ndarray]:
    """A template point (3,) mm on or near `carpal` (one of `PARTS`) carried onto a participant model:
    (its body's index into `BONES`, the point in the model's neutral pose), moved by the shift of the
    carpal's centre of mass and the cube root of its volume ratio (both in the RCS at neutral)."""
    owner = next(b for b in BONES if carpal in BODY_PARTS[b])
    mine = trimesh.Trimesh(*model.part_mesh(carpal), process=False)
    theirs = load_template().parts[carpal].trimesh(solid_only=True)
    scale = (mine.volume / theirs.volume) ** (1.0 / 3.0)
    return BONES.index(owner), mine.center_mass + scale * (np.asarray(site, dtype=np.float64) - theirs.center_mass)


def _lines(rig: str, model) -> tuple:
    tendons = load_tendons(rig)
    body, point = [], []
    for carpal, site in zip(tendons.carpal, tendons.point):
        b, p = carry_point(model, carpal, site)
        body.append(b)
        point.append(p)
    share = tendons.tension / tendons.tension.sum()
    arrays = (np.array(body, np.int64), np.array(point), tendons.direction.copy(), share)
    for a in arrays:
        a.setflags(write=False)
    return arrays


def model_lines(model, rig: str = "erhart2020") -> tuple:
    """The `rig`'s tendons as lines of action on a participant model: (body (n,) index into `BONES`,
    point (n, 3) mm in the model's neutral pose, direction (n, 3) unit pull, share (n,) of the total
    tension). Each template site moves with the carpal it loads (`carpal`, `carry_point`)."""
    if rig not in RIGS:
        raise ValueError(f"unknown tendon rig {rig!r}; known: {sorted(RIGS)}")
    key = (model.name, model.source_hash, rig)
    if key not in _LINES:
        _LINES[key] = _lines(rig, model)
    return _LINES[key]


def crossing(point: np.ndarray, direction: np.ndarray, y: float) -> np.ndarray:
    """Where the line through `point` (mm) along `direction` crosses the transverse plane at `y` (mm, RCS)."""
    return point + direction * ((y - point[1]) / direction[1])


@functools.cache
def _resultant_direction(rig: str) -> tuple:
    force = carpal_loads(load_tendons(rig), 1.0)["all"].force
    return tuple(force / np.linalg.norm(force))


def resultant_direction(rig: str = "erhart2020") -> np.ndarray:
    """The unit direction (3,) of the `rig`'s (a `RIGS` name) tendon resultant on the hand at
    neutral, RCS: the direction of the sum of its lines (`model_lines`), which a driver whose lines all
    load the driven distal row acts as."""
    if rig not in RIGS:
        raise ValueError(f"unknown tendon rig {rig!r}; known: {sorted(RIGS)}")
    return np.array(_resultant_direction(rig))
