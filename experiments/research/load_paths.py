"""Where the axial load goes at neutral (issues 10 and 33: the load path), and issue 54's step-0 diagnostics.

For each participant (population design, capitate held at neutral under the validation's 100 N), one
section per `--only` key:

- `paths`: the contact force on each bone of each contact pair's sample body (the distal row's parts,
  the triquetrum with the lunate) with the neutral gaps of those samples to the opposing surface, then
  the force and share of each articulation (`model.ARTICULATIONS`: the midcarpal shares against Viegas
  1993, the ulnar share against Palmer & Werner 1984) as `wrist-bench validate` checks them, and the
  space a TFCC would fill (`ulnocarpal_space`).
- `a` (issue 54, 0a): the moment the driver holds, by component (N·m, RCS: flexion + about z, ulnar
  deviation + about x, pronation + about y). It is the net moment of every force on the driven
  capitate + hamate body at the loaded run's equilibrium (contacts, ligaments, the RSC membrane, the
  tendon lines on it), about its centre of mass, summed by the solver's own force kernel
  (`outputs.driven_body_load`); the prescribed rotation supplies the opposite. Beside it the moment of
  the body's own tendon lines alone (closed form). Then the shares with one ray group loaded at a time
  (the rig's lines on the column, on the capitate, on the hamate: `tendons.CARPAL_OF`), each group's
  lines scaled to the same 100 N, and the trapeziocapitate contact and TZC ligament forces against the
  column's input (its lines' tension and the resultant's proximal component).
- `b` (0b): the ulnar variance (mm, + ulna plus) by the corner rule (`anatomy.ulnar_variance`) against the
  model's ulna, on myo-sim's original radius carried into the participant (the template's RCS, the
  participant's warp: the reading the build seats the ulna by) and on the model's whole radius, its
  rebuilt fossae (`anatomy.radius_cap`) included (what step 0 read).
- `c` (0c): the shares with the capitate + hamate body shifted ±`SEAT_SHIFT_MM` along the capitate's
  long axis (`capitate_axis`), two ways: the loaded driver's target moved (a check: its translations
  are free, so only the start moves), and the participant rebuilt with the body's bones moved (the
  cartilage, contact grids and ligament lengths follow the new gaps; cached like any build).
- `d` (0d): the shares under three load modes: the tendon rig (the default), the `axial` direction (one
  line on the capitate's centre of mass) and the hand loaded axially as in the Tencer/Viegas jig
  (`anatomy.jig`, the load validate's neutral checks take: 100 N along the radius' axis split among the
  distal carpals by their CMC articular areas measured on myo-sim's metacarpals, each part through its
  facets' centroid).
- `variance` (issue 54, step 1): the shares at neutral after an ulnar osteotomy of each of `OSTEOTOMIES_MM`
  (`BuildParams.ulnar_osteotomy_mm`: the participant rebuilt with its ulna moved along the radius' long
  axis after its TFCC layer is made at the participant's seat, as Werner 1986 shortened and lengthened
  the ulna of cadaver wrists; each model cached by its own hash), with the TFCC layer and the lunate's
  bone distance to the ulna; then the ulnar share's slope on each side beside Werner 1986's
  (`WERNER_1986`). `--tfc` rebuilds with other TFCC properties (`TFC_VARIANTS`): the filling layer at
  cartilage's stiffness, a disc of measured thickness.

Run: `python experiments/research/load_paths.py P1 [P2 ...] [--only paths,a,b,c,d,variance] [--load-direction erhart2020] [--tfc default|cartilage|disc]`
(`--load-direction`: the load of `paths`, `a`, `c` and `variance`: `settings.LOAD_DIRECTIONS`).
"""

from __future__ import annotations

import argparse
import dataclasses
import math

import numpy as np
import trimesh

from wrist_env import design
from wrist_env.anatomy import jig, tendons
from wrist_env.anatomy.template import load_template, oriented_parts
from wrist_env.anatomy.ulnar_variance import built_variance, ulnar_variance
from wrist_env.builder.params import BuildParams
from wrist_env.builder.warp import Warp
from wrist_env.errors import BuildError
from wrist_env.ligaments import ALL_LIGAMENT_NAMES
from wrist_env.model import BODY_PARTS, BONES, CAPITATE, MIDCARPAL, PAIR_BONES, PAIRS, Model
from wrist_env.participants import builtin, cache, registry
from wrist_env.participants.registry import load_model
from wrist_env.solver import drivers
from wrist_env.solver import simulate as sim
from wrist_env.solver.contact import OUTSIDE_MM, sdf_lookup
from wrist_env.solver.outputs import articulation_forces, driven_body_load, pair_slice, pressure_map, sample_parts
from wrist_env.solver.settings import DEFAULT_LOADS, LOAD_DIRECTIONS
from wrist_env.validation import NEUTRAL_LOAD_N, load_shares_pct


def signed_distance(model, b: int, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed distance (mm, NaN off the grid) and its gradient (n, 3) of body b's contact grid (cartilage
    folded in) at neutral-pose points (n, 3): the solver's own trilinear look-up."""
    shape, origin, h = model.grid_shape[b], model.grid_origin[b], float(model.grid_spacing[b])
    values = np.ascontiguousarray(model.grid_values, dtype=np.float32)
    offset = int(model.grid_offsets[b])
    d, grad = np.empty(len(points)), np.empty((len(points), 3))
    for i, q in enumerate(np.asarray(points, dtype=np.float64)):
        d[i], grad[i] = sdf_lookup(values, offset, shape, origin, h, q)
    d[d >= OUTSIDE_MM] = np.nan
    return d, grad


def part_gaps(name: str, model, poses) -> list[dict]:
    """Per pair and sample-body part: contact force (N, pressure × area), sample area (mm²), neutral gap (mm)."""
    load = pressure_map(model, poses) * model.sample_area
    rows = []
    for k, pair in enumerate(PAIRS):
        body, grid_body = PAIR_BONES[k]
        owner, s = sample_parts(model, pair), pair_slice(model, pair)
        gap = signed_distance(model, grid_body, model.sample_points[s])[0]
        for q, part_name in enumerate(BODY_PARTS[BONES[body]]):
            mine = owner == q
            if mine.any():
                rows.append(
                    {
                        "pair": pair,
                        "part": part_name,
                        "force_n": float(load[s][mine].sum()),
                        "area_mm2": float(model.sample_area[s][mine].sum()),
                        "gap_min_mm": float(np.nanmin(gap[mine])),
                        "gap_median_mm": float(np.nanmedian(gap[mine])),
                    }
                )
    return rows


def _body(model, b):
    lo, hi = model.vertex_offsets[b], model.vertex_offsets[b + 1]
    faces = model.faces[model.face_offsets[b] : model.face_offsets[b + 1]]
    return model.vertices[lo:hi], faces, model.vertex_part[lo:hi]


def ulnocarpal_space(model) -> dict:
    """Where a TFCC would sit, at neutral: the closest approach (mm) of the lunate and of the triquetrum
    to the ulna's surface, and the ulnar variance (mm, + ulna plus) the build seated the ulna at, its
    osteotomy included (`recorded_variance`)."""
    ulna_v, ulna_f, _ = _body(model, BONES.index("ulna"))
    lunate_v, _, part = _body(model, BONES.index("lunate"))
    _, distance, _ = trimesh.proximity.closest_point(trimesh.Trimesh(ulna_v, ulna_f, process=False), lunate_v)
    out = {f"{p}_to_ulna_mm": float(distance[part == q].min()) for q, p in enumerate(BODY_PARTS["lunate"])}
    return out | {"ulnar_variance_mm": recorded_variance(model)}


def recorded_variance(model) -> float:
    """The ulnar variance (mm) the build seated the ulna at plus its osteotomy; NaN where the corner rule
    found no corner or head (`ulnar_variance.built_variance`)."""
    v = built_variance(model.report)
    return math.nan if v is None else v


# --- shared: one neutral run and its shares ---------------------------------------------------------

NM = 1e-3  # N·mm -> N·m
COMPONENTS = (("flexion (+) about z", 2), ("ulnar deviation (+) about x", 0), ("pronation (+) about y", 1))
SHORT = {"scaphotrapeziotrapezoid": "STT", "scaphocapitate": "SC", "lunocapitate": "LC", "triquetrohamate": "TH"}


def neutral(model, driver):
    """The population design at neutral under `driver` (`drivers.loaded` at `NEUTRAL_LOAD_N`)."""
    result = sim.simulate(model, design.population(), driver)
    if not result.ok:
        raise RuntimeError(f"{model.name}: {result.message}")
    return result


def shares(model, result) -> dict:
    """STT, SC, LC, TH (% of the midcarpal sum), ulnar (% of radiocarpal + ulnocarpal), RS/RL."""
    f, s = articulation_forces(model, result.poses[0]), load_shares_pct(model, result)
    return {SHORT[k]: s[k] for k in MIDCARPAL} | {
        "ulnar": s["ulnocarpal"],
        "RS/RL": f["radioscaphoid"] / f["radiolunate"],
    }


def share_cells(row: dict) -> str:
    return " | ".join(f"{row[k]:.1f}" for k in ("STT", "SC", "LC", "TH", "ulnar")) + f" | {row['RS/RL']:.2f}"


SHARE_HEAD = "STT (%) | SC (%) | LC (%) | TH (%) | ulnar (%) | RS/RL"


def held_moment(model, driver, result) -> np.ndarray:
    """What the driver holds (N·mm, RCS, about the capitate's centre of mass): see the module, `a`."""
    return driven_body_load(model, design.population(), driver, result.poses[0], result.membrane_nodes[0])[1]


def with_lines(driver, keep: np.ndarray):
    """`driver` with only its lines where `keep`, their shares scaled to sum 1 (the same total)."""
    lines = driver.loads
    share = lines.share[keep] / lines.share[keep].sum()
    sub = dataclasses.replace(
        lines, body=lines.body[keep], point=lines.point[keep], direction=lines.direction[keep], share=share
    )
    return dataclasses.replace(driver, loads=sub)


# --- a: the held moment, one ray group at a time, the trapeziocapitate wedge ------------------------

GROUPS = (
    ("column (trapezium + trapezoid)", ("trapezium", "trapezoid")),
    ("capitate", ("capitate",)),
    ("hamate", ("hamate",)),
)


def held_rows(model, rig: str) -> list[dict]:
    """Per component: the moment the driver holds and the capitate body's own lines' moment (N·m)."""
    driver = drivers.loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N, direction=rig)
    result = neutral(model, driver)
    force, moment = driven_body_load(model, design.population(), driver, result.poses[0], result.membrane_nodes[0])
    lines = driver.loads
    mine = lines.body == CAPITATE
    arm = np.einsum("ij,nj->ni", result.poses[0, CAPITATE, :3, :3], lines.point[mine] - model.com[CAPITATE])
    own = np.cross(arm, driver.load(0)[mine, None] * lines.direction[mine]).sum(axis=0)
    rows = [{"component": c, "held_nm": moment[k] * NM, "lines_nm": own[k] * NM} for c, k in COMPONENTS]
    rows.append(
        {"component": "magnitude", "held_nm": np.linalg.norm(moment) * NM, "lines_nm": np.linalg.norm(own) * NM}
    )
    return rows + [
        {
            "component": "net force on the body (N, equilibrium check)",
            "held_nm": np.linalg.norm(force),
            "lines_nm": np.nan,
        }
    ]


def group_of(rig: str) -> np.ndarray:
    """The carpal each of the rig's lines loads (`tendons.CARPAL_OF`), in `model_lines` order."""
    return np.array(tendons.load_tendons(rig).carpal)


def column_rows(model, result, driver, carpal) -> dict:
    """The trapeziocapitate contact and TZC ligament forces (N) against the column's input: its lines'
    tension and the proximal (+y) component of their resultant (N)."""
    col = np.isin(carpal, ("trapezium", "trapezoid"))
    tension = driver.load(0)[col]
    f = articulation_forces(model, result.poses[0])
    bundle = dict(zip(ALL_LIGAMENT_NAMES, result.bundle_force[0]))
    return {
        "column_tension_n": float(tension.sum()),
        "column_axial_n": float((tension[:, None] * driver.loads.direction[col]).sum(axis=0)[1]),
        "trapeziocapitate_n": f["trapeziocapitate"],
        "stt_n": f["scaphotrapeziotrapezoid"],
        "tzc_p_n": float(bundle["TZC_p"]),
        "tzc_d_n": float(bundle["TZC_d"]),
    }


def group_rows(model, rig: str) -> list[dict]:
    """The shares, the held moment (N·m) and the column's forces with all the rig's lines, then one ray
    group's lines at a time at the same total (`NEUTRAL_LOAD_N`)."""
    full = drivers.loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N, direction=rig)
    carpal = group_of(rig)
    rows = []
    for label, parts in (("all (the rig)", tuple(set(carpal))),) + GROUPS:
        keep = np.isin(carpal, parts)
        driver = full if keep.all() else with_lines(full, keep)
        result = neutral(model, driver)
        sub = carpal[keep]
        row = {"group": label, "rig_share_pct": 100.0 * full.loads.share[keep].sum()}
        row |= shares(model, result) | {"held_nm": held_moment(model, driver, result) * NM}
        row |= column_rows(model, result, driver, sub)
        rows.append(row)
    return rows


# --- b: the ulnar variance on the rebuilt and the original radius -----------------------------------


def variance_rows(name: str, model) -> list[dict]:
    """The corner rule (`ulnar_variance`) on myo-sim's original radius (the template's RCS, then the
    built-in participant's warp) and on the model's whole radius (its rebuilt fossae included), both
    against the model's ulna."""
    ulna_v = _body(model, BONES.index("ulna"))[0]
    rebuilt = ulnar_variance(_body(model, BONES.index("radius"))[0], ulna_v)
    parts, _ = oriented_parts()
    original = np.asarray(parts["radius"].vertices) + load_template().rcs_from_myosim[:3, 3]
    if name in builtin.BUILTIN:
        original = Warp.from_dict(builtin.info(name).warp).apply(original)
    mine = ulnar_variance(original, ulna_v)
    return [
        {
            "radius": "the model's, its rebuilt fossae included",
            "variance": rebuilt[0],
            "corner_y": rebuilt[1],
            "head_y": rebuilt[2],
        },
        {"radius": "myo-sim's original", "variance": mine[0], "corner_y": mine[1], "head_y": mine[2]},
    ]


# --- c: the seat ------------------------------------------------------------------------------------

SEAT_SHIFT_MM = 0.25


def capitate_axis(model) -> np.ndarray:
    """The capitate's long axis (unit, RCS, pointing proximal: +y): the principal axis of least moment of
    inertia of the capitate bone's closed mesh (the hamate left out) at neutral."""
    mesh = trimesh.Trimesh(*model.part_mesh("capitate"), process=False)
    axis = mesh.principal_inertia_vectors[np.argmin(mesh.principal_inertia_components)]
    return axis if axis[1] > 0 else -axis


def shifted_model(name: str, shift_mm: float, axis: np.ndarray) -> Model:
    """The participant rebuilt with its capitate body (capitate + hamate) moved `shift_mm` along `axis`
    (the other bones where they were), cached by its inputs' hash as `registry.load_model` caches."""
    from wrist_env.builder.digest import source_hash
    from wrist_env.builder.pipeline import build_model

    params = BuildParams()
    bones = dict(registry.bones(name, params))
    cap = bones["capitate"]
    v = cap.vertices + shift_mm * axis
    v.setflags(write=False)
    bones["capitate"] = dataclasses.replace(cap, vertices=v)
    digest = source_hash(name, bones, params)
    path = cache.cache_dir() / f"{name}-{digest}"
    if path.with_suffix(".json").exists():
        return Model.load(path)
    model = build_model(name, bones, params, digest=digest, progress=False)
    model.save(path)
    return model


def _lc_gap(model) -> float:
    """The capitolunate facet's bone-to-bone closest approach at neutral (mm): the lunate bone's vertices
    to the capitate bone's surface (the seat's measure, `midcarpal.facet_gaps`; 1.23 mm on the template)."""
    import igl

    lunate = model.part_mesh("lunate")[0]
    v, f = model.part_mesh("capitate")
    return float(np.sqrt(igl.point_mesh_squared_distance(lunate, v, np.asarray(f, np.int64))[0].min()))


def seat_rows(name: str, model, rig: str) -> tuple[list[dict], np.ndarray]:
    """The shares as built, at the driver's target shifted, and at the rebuilt seat, by ∓`SEAT_SHIFT_MM`
    (+: proximal, into the proximal row), with the capitate's smallest neutral gap to the lunate."""
    axis = capitate_axis(model)
    base = drivers.loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N, direction=rig)
    result = neutral(model, base)
    rows = [{"how": "as built", "shift": 0.0, "lc_gap": _lc_gap(model)} | shares(model, result)]
    for shift in (-SEAT_SHIFT_MM, SEAT_SHIFT_MM):
        moved = dataclasses.replace(base, com=base.com + shift * axis)
        result = neutral(model, moved)
        rows.append({"how": "driver's target", "shift": shift, "lc_gap": _lc_gap(model)} | shares(model, result))
    for shift in (-SEAT_SHIFT_MM, SEAT_SHIFT_MM):
        m = shifted_model(name, shift, axis)
        result = neutral(m, drivers.loaded(m, [np.eye(3)], load_n=NEUTRAL_LOAD_N, direction=rig))
        rows.append({"how": "rebuilt seat", "shift": shift, "lc_gap": _lc_gap(m)} | shares(m, result))
    return rows, axis


# --- d: the load mode -------------------------------------------------------------------------------


def mode_rows(model) -> list[dict]:
    """The shares and the held moment (N·m) under the tendon rig, one axial line on the capitate, and the
    hand loaded axially as in a jig (`anatomy.jig`: split by CMC area; validate's neutral load)."""
    rows = []
    for label, direction in (
        ("tendon rig (erhart2020)", "erhart2020"),
        ("axial: one line on the capitate's centre", "axial"),
        ("jig: the hand axial, by CMC area (validate's)", "jig"),
    ):
        driver = drivers.loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N, direction=direction)
        result = neutral(model, driver)
        rows.append({"mode": label} | shares(model, result) | {"held_nm": held_moment(model, driver, result) * NM})
    return rows


def print_paths(name, model, load_direction) -> None:
    driver = drivers.loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N, direction=load_direction)
    result = sim.simulate(model, design.population(), driver)
    total = driver.resultant(0)
    print(
        f"{name}, population design, neutral, {NEUTRAL_LOAD_N:g} N on the {load_direction} lines, resultant {total.round(2)} N"
    )
    print("| pair | part | force (N) | sample area (mm²) | neutral gap min / median (mm) |\n|---|---|---|---|---|")
    for r in part_gaps(name, model, result.poses[0]):
        print(
            f"| {r['pair']} | {r['part']} | {r['force_n']:.2f} | {r['area_mm2']:.0f} | "
            f"{r['gap_min_mm']:.2f} / {r['gap_median_mm']:.2f} |"
        )
    forces, pct = articulation_forces(model, result.poses[0]), load_shares_pct(model, result)
    print("\n| articulation | force (N) | share (%) |\n|---|---|---|")
    for joint, force in forces.items():
        share = f"{pct[joint]:.1f}" if joint in pct else ""
        print(f"| {joint} | {force:.2f} | {share} |")
    space = ulnocarpal_space(model)
    print(
        f"\nulnocarpal space: lunate {space['lunate_to_ulna_mm']:.2f} mm and triquetrum "
        f"{space['triquetrum_to_ulna_mm']:.2f} mm from the ulna; ulnar variance {space['ulnar_variance_mm']:+.2f} mm"
    )
    rs, rl = forces["radioscaphoid"], forces["radiolunate"]
    print(
        f"\nRS/RL force ratio {rs / rl:.2f}; midcarpal shares of the four midcarpal joints, ulnocarpal of RS + RL + ulnocarpal\n"
    )


def print_a(name, model, rig) -> None:
    print(
        f"\n{name} (0a): the moment the driver holds at neutral, {NEUTRAL_LOAD_N:g} N on the {rig} lines (N·m, RCS, about the capitate's centre of mass)"
    )
    print("| component | held (net moment on the driven body) | the body's own tendon lines alone |\n|---|---|---|")
    for r in held_rows(model, rig):
        lines = "" if np.isnan(r["lines_nm"]) else f"{r['lines_nm']:+.3f}"
        print(f"| {r['component']} | {r['held_nm']:+.3f} | {lines} |")
    print(
        f"\n{name} (0a): one ray group's lines at a time, scaled to {NEUTRAL_LOAD_N:g} N (population design, neutral)"
    )
    print(
        f"| lines | their share of the rig (%) | {SHARE_HEAD} | held flex / uln. dev. / pron. (N·m) | column's lines: tension / proximal (N) "
        "| STT (N) | trapeziocapitate (N) | TZC_p / TZC_d (N) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    )
    for r in group_rows(model, rig):
        h = r["held_nm"]
        print(
            f"| {r['group']} | {r['rig_share_pct']:.0f} | {share_cells(r)} | {h[2]:+.3f} / {h[0]:+.3f} / {h[1]:+.3f} | "
            f"{r['column_tension_n']:.1f} / {r['column_axial_n']:.1f} | {r['stt_n']:.1f} | {r['trapeziocapitate_n']:.1f} | "
            f"{r['tzc_p_n']:.1f} / {r['tzc_d_n']:.1f} |"
        )


def print_b(name, model) -> None:
    print(f"\n{name} (0b): ulnar variance by the corner rule (`ulnar_variance`; + ulna plus), against the model's ulna")
    print(
        "| radius | ulnar variance (mm) | radius' ulnar corner y (mm) | ulnar head's most distal y (mm) |\n|---|---|---|---|"
    )
    rows = variance_rows(name, model)
    for r in rows:
        print(f"| {r['radius']} | {r['variance']:+.2f} | {r['corner_y']:+.2f} | {r['head_y']:+.2f} |")
    print(f"read on the rebuilt fossae, the variance would be {rows[0]['variance'] - rows[1]['variance']:+.2f} mm off")


def print_c(name, model, rig) -> None:
    rows, axis = seat_rows(name, model, rig)
    print(
        f"\n{name} (0c): the capitate + hamate body shifted along the capitate's long axis {np.round(axis, 3)} (RCS, + proximal), "
        f"{NEUTRAL_LOAD_N:g} N on the {rig} lines"
    )
    print(
        f"| how | shift (mm) | capitolunate bone gap at neutral (mm) | {SHARE_HEAD} |\n|---|---|---|---|---|---|---|---|---|"
    )
    for r in rows:
        print(f"| {r['how']} | {r['shift']:+.2f} | {r['lc_gap']:+.3f} | {share_cells(r)} |")


def print_d(name, model) -> None:
    print(f"\n{name} (0d): the load mode at neutral, {NEUTRAL_LOAD_N:g} N (population design)")
    print(f"| mode | {SHARE_HEAD} | held flex / uln. dev. / pron. (N·m) |\n|---|---|---|---|---|---|---|---|")
    for r in mode_rows(model):
        h = r["held_nm"]
        print(f"| {r['mode']} | {share_cells(r)} | {h[2]:+.3f} / {h[0]:+.3f} / {h[1]:+.3f} |")


# --- variance (issue 54, step 1): the shares against the ulnar variance -----------------------------

OSTEOTOMIES_MM = (-2.5, -1.25, 0.0, 1.25, 2.5)
WERNER_1986 = {"neutral_pct": 18.4, "shortening_per_mm": 5.6, "lengthening_per_mm": 9.4}
"""Werner 1986 (cadavers, the disc intact), as the load-path study (§6, step 1) quotes it: the ulnar share
18.4 % at neutral variance, falling about 5.6 points per mm of ulnar shortening and rising about 9.4 per
mm of lengthening (4.3 % at −2.5 mm, 41.9 % at +2.5 mm)."""
TFC_DISC_MM = 1.4
"""A TFC disc's measured thickness: the median 1.4 mm of 24 wrists on MRI at a median variance of −0.7 mm
(J Hand Surg Eur 2022;47:722; the load-path study's 1.4–2 mm)."""
TFC_VARIANTS = {
    "default": {},
    "cartilage": {"tfc_modulus_ratio": 1.0},
    "disc": {"tfc_disc_mm": TFC_DISC_MM},
}
"""TFCC properties `--tfc` may rebuild with (`BuildParams` fields): the default (the layer filling the
ulnocarpal space at fibrocartilage's stiffness), the layer at cartilage's stiffness, a disc of measured
thickness (`TFC_DISC_MM`) at fibrocartilage's."""


def werner_share(osteotomy_mm: float) -> float:
    """The ulnar share (%) Werner 1986's slopes give `osteotomy_mm` from neutral variance (`WERNER_1986`)."""
    w = WERNER_1986
    slope = w["shortening_per_mm"] if osteotomy_mm < 0 else w["lengthening_per_mm"]
    return w["neutral_pct"] + slope * osteotomy_mm


def variance_model(name: str, osteotomy_mm: float, tfc: str = "default") -> Model:
    """The participant built with `TFC_VARIANTS[tfc]` and an ulnar osteotomy of `osteotomy_mm`, cached by
    its hash."""
    return load_model(name, BuildParams(ulnar_osteotomy_mm=osteotomy_mm, **TFC_VARIANTS[tfc]))


def variance_sweep(name: str, rig: str, tfc: str = "default") -> list[dict]:
    """Per osteotomy (`OSTEOTOMIES_MM`): the variance then, the TFCC layer's thickness (mm: min / mean /
    max), the lunate's bone distance to the ulna (mm), the shares."""
    rows = []
    for o in OSTEOTOMIES_MM:
        row = {"osteotomy": o}
        try:
            model = variance_model(name, o, tfc)
        except BuildError as e:
            rows.append(row | {"error": str(e)})
            continue
        space = ulnocarpal_space(model)
        row |= {"variance": space["ulnar_variance_mm"], "tfcc": model.report["tfcc_thickness_mm"]}
        row["lunate_gap"] = space["lunate_to_ulna_mm"]
        try:
            result = neutral(model, drivers.loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N, direction=rig))
        except RuntimeError as e:
            rows.append(row | {"error": str(e)})
            continue
        rows.append(row | shares(model, result))
    return rows


def print_variance(name, rig, tfc: str = "default") -> None:
    print(
        f"\n{name} (variance, TFCC {tfc}: {TFC_VARIANTS[tfc] or 'as built'}): an ulnar osteotomy from the "
        f"participant's seat (`BuildParams.ulnar_osteotomy_mm`), population design, neutral, {NEUTRAL_LOAD_N:g} N "
        f"on the {rig} lines"
    )
    print(
        f"| osteotomy (mm, + lengthening) | variance (mm) | TFCC layer min / mean / max (mm) "
        f"| lunate to ulna, bone (mm) | {SHARE_HEAD} | Werner 1986 ulnar (%) |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|"
    )
    rows = variance_sweep(name, rig, tfc)
    for r in rows:
        asked = f"{r['osteotomy']:+.2f}"
        if "variance" not in r:
            print(f"| {asked} | build refused: {r['error']} |")
            continue
        t = r["tfcc"]
        head = f"| {asked} | {r['variance']:+.2f} | {t['min']:.2f} / {t['mean']:.2f} / {t['max']:.2f} | {r['lunate_gap']:.2f} |"
        if "error" in r:
            print(f"{head} simulation failed: {r['error']} |")
            continue
        print(f"{head} {share_cells(r)} | {werner_share(r['osteotomy']):.1f} |")
    by = {r["osteotomy"]: r["ulnar"] for r in rows if "ulnar" in r}
    lo, mid, hi = OSTEOTOMIES_MM[0], 0.0, OSTEOTOMIES_MM[-1]
    if {lo, mid, hi} <= set(by):
        short, long = (by[mid] - by[lo]) / (mid - lo), (by[hi] - by[mid]) / (hi - mid)
        print(
            f"ulnar share's slope: {short:+.2f} points/mm of shortening to {lo:+g} mm (Werner 1986: "
            f"{WERNER_1986['shortening_per_mm']:+.1f}), {long:+.2f} points/mm of lengthening to {hi:+g} mm "
            f"(Werner: {WERNER_1986['lengthening_per_mm']:+.1f}); at the seat {by[mid]:.1f} % (Werner at neutral: "
            f"{WERNER_1986['neutral_pct']:.1f} %)."
        )


SECTIONS = ("paths", "a", "b", "c", "d", "variance")


def main(names, load_direction: str = DEFAULT_LOADS, only=SECTIONS, tfc: str = "default") -> None:
    if "d" in only:
        facets = jig.cmc_facets()
        total = sum(f["area"] for f in facets.values())
        print("CMC articular areas (template, myo-sim's metacarpals; the jig's axial load is split by them):")
        print("| carpal | facing | area (mm²) | share (%) |\n|---|---|---|---|")
        for c, f in facets.items():
            mcs = ", ".join(m.replace("_r", "") for m in f["metacarpals"])
            print(f"| {c} | {mcs} | {f['area']:.0f} | {100 * f['area'] / total:.1f} |")
    for name in names:
        model = load_model(name)
        if "paths" in only:
            print_paths(name, model, load_direction)
        if "a" in only:
            print_a(name, model, load_direction)
        if "b" in only:
            print_b(name, model)
        if "c" in only:
            print_c(name, model, load_direction)
        if "d" in only:
            print_d(name, model)
        if "variance" in only:
            print_variance(name, load_direction, tfc)


def _sections(text: str) -> tuple:
    keys = tuple(k.strip() for k in text.split(",") if k.strip())
    bad = [k for k in keys if k not in SECTIONS]
    if bad or not keys:
        raise argparse.ArgumentTypeError(f"--only takes a comma-separated list of {SECTIONS}, but got {text!r}")
    return keys


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("participants", nargs="*", default=["P1"])
    parser.add_argument("--load-direction", choices=LOAD_DIRECTIONS, default=DEFAULT_LOADS)
    parser.add_argument(
        "--only", type=_sections, default=SECTIONS, help=f"sections to print, comma-separated: {','.join(SECTIONS)}"
    )
    parser.add_argument(
        "--tfc", choices=tuple(TFC_VARIANTS), default="default", help="the TFCC properties of `variance`'s builds"
    )
    args = parser.parse_args()
    main(args.participants, args.load_direction, args.only, args.tfc)
