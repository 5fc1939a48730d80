"""Build a participant `Model` from its bones (preprint 2.2.1–2.2.2), as a recipe.

morph the annotated template → transfer coverage and ligament sites →
cartilage thickness, overclosure removal, wedges → ligament fibres and the RSC
membrane → contact law → signed-distance grids and contact samples → mass.
"""

from __future__ import annotations

import os
import time

import numpy as np
import trimesh
from scipy.spatial import cKDTree
from tqdm import tqdm

from wrist_env.anatomy.annotations import read_annotation_data, template_annotations
from wrist_env.anatomy.template import closed, load_template
from wrist_env.anatomy.ulnar_variance import moved_ulna, radius_bone, seat_ulna, ulnar_variance
from wrist_env.builder import cartilage, contact_law, fibres, mass, morph, sdf
from wrist_env.builder.contact_samples import _contact_samples, _seat_samples
from wrist_env.builder.digest import source_hash
from wrist_env.builder.handedness import check_side
from wrist_env.builder.params import BuildParams
from wrist_env.builder.surface import displaced_vertices, extrusion_directions, gap_to, grnn_smooth
from wrist_env.errors import BuildError
from wrist_env.ligaments import ALL_LIGAMENTS, BODY_LIGAMENTS, LIGAMENT_NAMES, LIGAMENTS, RSC_INDEX
from wrist_env.model import BONES, PAIRS, Model, offsets

BUILD_STEPS = ("morph", "cartilage", "ligaments", "contact_law", "grids", "mass")  # timed in the report
GRID_BONES = ("radius", "ulna", "scaphoid", "lunate", "capitate", "hamate")
TFCC = "ulnocarpal"
"""The pair through the TFCC: its articular disc and meniscus homologue fill the ulnocarpal space
between the ulnar head and the lunate and triquetrum (Palmer & Werner 1981), so the disc is a layer
on the ulnar head as thick as that space at neutral (`tfcc_thickness`), under the cartilage law."""
MIN_SITE_VERTICES = 8
JOINT_SPACE_MM = {art: (0.3, 4.0) for art in PAIRS} | {"scapholunate": (0.3, 8.0)}
"""Plausible neutral joint space per articulation (mm; the median bone-to-bone gap over its cartilage
coverage, `cartilage.build_cartilage`). Normal radiocarpal and intercarpal spaces are ~1.5–2 mm
(Gilula 1979: ~2 mm; a normal scapholunate interval is under 2 mm, Hand (N Y) 2018;13(6):671–677), the
built-in P1–P3 1.5–2.5 mm. The bounds leave room for variation and disease: under 0.3 mm no cartilage
fits; a scapholunate gap over 3–4 mm is a dissociation, so that one may reach 8 mm. Outside them the
bones do not sit as the template's do: right-hand meshes declared left measured 13–16 mm in three or
four articulations (issue 11)."""


def _morph_one(args):
    tv, tf, pv, pf, seed = args
    return morph.morph(tv, tf, pv, pf, seed=seed)


def _morph_all(bones: dict, params: BuildParams, workers: int) -> tuple[dict, dict]:
    """Morph every template bone onto the participant's, largest first, on `workers` processes."""
    seed = params.seed
    template = load_template(*params.anatomy).bones
    order = sorted(BONES, key=lambda b: -len(template[b].vertices))
    jobs = [(template[b].vertices, template[b].faces, bones[b].vertices, bones[b].faces, seed) for b in order]
    if workers > 1:
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(max_workers=workers) as pool:
            done = list(pool.map(_morph_one, jobs))
    else:
        done = [_morph_one(j) for j in jobs]
    results = dict(zip(order, done))
    report = {b: {"mean": round(results[b].error_mean_mm, 4), "max": round(results[b].error_max_mm, 4)} for b in BONES}
    return results, report


def _transfer(morphs: dict, bones: dict, params: BuildParams) -> tuple[dict, dict, list]:
    """Coverage and ligament site masks on the participant's bones, and the sites relocated.

    A site whose morphed patch finds too few participant vertices (a bone mesh
    cut shorter than the template's) is placed on the participant vertices
    nearest the morphed patch instead.
    """
    ann = template_annotations(*params.anatomy)
    coverage = {}
    for art, (a, b, ma, mb) in ann.coverage.items():
        coverage[art] = (
            a,
            b,
            morph.transfer_mask(morphs[a], ma, bones[a].vertices) & bones[a].solid,
            morph.transfer_mask(morphs[b], mb, bones[b].vertices) & bones[b].solid,
        )
    sites, relocated = {}, []
    for lig, (o, i) in ann.sites.items():
        pair = []
        for site in (o, i):
            target = bones[site.bone].vertices
            mask = morph.transfer_mask(morphs[site.bone], site.mask, target)
            if mask.sum() < MIN_SITE_VERTICES:
                patch = morphs[site.bone].vertices[site.mask]
                _, nearest = cKDTree(target).query(patch)
                mask = np.zeros(len(target), bool)
                mask[nearest] = True
                relocated.append(f"{lig}@{site.bone}")
            pair.append((site.bone, mask))
        sites[lig] = tuple(pair)
    return coverage, sites, relocated


def _ligaments(bones: dict, sites: dict, params: BuildParams):
    bundles, membrane = [], None
    for k, lig in enumerate(ALL_LIGAMENTS):
        optional = lig not in LIGAMENTS and lig.name not in BODY_LIGAMENTS
        if lig.name not in sites or (optional and not params.fixed_ligaments):
            continue  # a fixed TC/TH, in a model without the distal row or without them
        (ob, om), (ib, im) = sites[lig.name]
        if lig.fibres == 0:
            scaphoid = trimesh.Trimesh(bones["scaphoid"].vertices, bones["scaphoid"].faces, process=False)
            membrane = fibres.build_membrane(
                bones[ob].vertices[om],
                bones[ib].vertices[im],
                scaphoid,
                n_along=params.membrane_along,
                n_across=params.membrane_across,
            )
            continue
        bundles.append(
            (
                k,
                ob,
                ib,
                fibres.build_bundle(
                    lig.name,
                    bones[ob].vertices[om],
                    bones[ib].vertices[im],
                    lig.fibres,
                    params.seed + k,
                    origin_vertex_ids=np.flatnonzero(om),
                    insertion_vertex_ids=np.flatnonzero(im),
                ),
            )
        )
    return bundles, membrane


ABSENT_WITHOUT_DISTAL_ROW = ("triquetrohamate",)
"""Articulations a model without the distal row (`BuildParams.distal_row`) has no cartilage of: the
triquetrohamate pair is the lunate body's triquetrum on the hamate; its pair stays, without samples."""


def tfcc_thickness(
    bones: dict, thickness: dict, coverage: tuple, bandwidth_mm: float, disc_mm: float | None = None
) -> tuple[np.ndarray, dict]:
    """The TFCC as a layer on the ulnar head (`TFCC`): per ulna vertex (mm, zero off its coverage) the
    distance along its extrusion direction (`surface.extrusion_directions`) to the lunate body's
    cartilage surface (the closest distance where that ray misses or runs beyond the coverage's
    max_gap_mm), smoothed over the patch (`surface.grnn_smooth`), and no thicker than `disc_mm` (None:
    the space filled); and its min/mean/max."""
    a, _, mask_a, mask_b = coverage
    ulna, carpal = (mask_a, mask_b) if a == "ulna" else (mask_b, mask_a)
    head, lunate = bones["ulna"], bones["lunate"]
    surface = displaced_vertices(lunate.vertices, lunate.faces, thickness["lunate"])
    gap = gap_to(head.vertices, ulna, surface, lunate.faces, carpal)[0]
    origins = head.vertices[ulna]
    rays = extrusion_directions(head.vertices, head.faces, ulna)[ulna]
    target = trimesh.Trimesh(surface, lunate.faces, process=False)
    hits, ray_ids, _ = target.ray.intersects_location(origins, rays, multiple_hits=False)
    along = np.einsum("ij,ij->i", hits - origins[ray_ids], rays[ray_ids])
    reach = read_annotation_data()["cartilage"][TFCC]["max_gap_mm"]  # a grazing ray leaves the space
    gap[ray_ids] = np.where((along > 0) & (along <= reach), along, gap[ray_ids])
    out = np.zeros(len(head.vertices))
    out[ulna] = grnn_smooth(origins, gap, bandwidth_mm)
    if disc_mm is not None:
        out[ulna] = np.minimum(out[ulna], disc_mm)
    layer = out[ulna]
    report = {k: round(float(f(layer)), 4) for k, f in (("min", np.min), ("mean", np.mean), ("max", np.max))}
    return out, report | {"rays_hit": int(len(ray_ids)), "vertices": int(ulna.sum())}


def _osteotomy(bones: dict, lengthening_mm: float) -> dict:
    """`bones` with the ulna moved `lengthening_mm` distally along the radius' long axis
    (`BuildParams.ulnar_osteotomy_mm`); its vertex masks, cartilage and TFCC layer move with it."""
    return bones if lengthening_mm == 0.0 else moved_ulna(bones, -lengthening_mm)


def _seat_ulna(name: str, bones: dict, variance_mm: float | None) -> tuple[dict, dict | None]:
    """The bones with the ulna seated at `variance_mm` (`BuildParams.ulnar_variance_mm`; None: where the
    bones put it), before its morph, TFCC layer, grid and ligament sites are made from it, and the
    variance as given and seated (None where the corner rule finds no corner or head: a folder's meshes
    cut otherwise; then a variance asked is a `BuildError`)."""
    try:
        if variance_mm is not None:
            return seat_ulna(bones, variance_mm)
        v = round(ulnar_variance(radius_bone(bones["radius"]), bones["ulna"].vertices).variance_mm, 4)
        return bones, {"given": v, "seated": v, "shift_mm": 0.0}
    except ValueError as e:
        if variance_mm is None:
            return bones, None
        raise BuildError(f"participant {name!r}: ulnar variance {variance_mm:g} mm cannot be seated: {e}") from None


def build_model(
    name: str,
    bones: dict,
    params: BuildParams | None = None,
    *,
    workers: int | None = None,
    digest: str | None = None,
    progress: bool = True,
) -> Model:
    """Build the participant model from its bones (name -> BoneSurface, RCS mm, neutral pose).

    workers: processes for the morphs (default: the machine's cores, at most 2). progress: a
    progress bar of the build's steps on stderr (~30-45 s in all).
    """
    params = params or BuildParams()
    workers = min(2, os.cpu_count() or 1) if workers is None else workers
    missing = [b for b in BONES if b not in bones]
    if missing:
        raise BuildError(f"participant {name!r} lacks bones {missing}")
    clock = time.perf_counter()
    timings = {}
    bar = tqdm(total=len(BUILD_STEPS), desc=f"building {name}", unit="step", disable=not progress, leave=False)
    bar.set_postfix_str(BUILD_STEPS[0])

    def lap(step):
        nonlocal clock
        now = time.perf_counter()
        timings[step] = round(now - clock, 3)
        clock = now
        bar.update(1)
        following = BUILD_STEPS.index(step) + 1
        bar.set_postfix_str(BUILD_STEPS[following] if following < len(BUILD_STEPS) else "done")

    bones = {**bones, "ulna": closed(bones["ulna"])}  # an open ulna's head, closed for its grid (the TFCC)
    check_side(name, load_template(*params.anatomy).bones, bones, params.seed)  # before the minute of morphing
    bones, variance = _seat_ulna(name, bones, params.ulnar_variance_mm)
    morphs, morph_report = _morph_all(bones, params, workers)
    lap("morph")
    coverage, sites, relocated = _transfer(morphs, bones, params)
    if not params.distal_row:  # the lunate without its triquetrum reaches no hamate (a type I lunate)
        coverage = {art: c for art, c in coverage.items() if art not in ABSENT_WITHOUT_DISTAL_ROW}
    articulations = {(a, b): (ma, mb) for art, (a, b, ma, mb) in coverage.items() if art != TFCC}
    verts = {b: bones[b].vertices for b in BONES}
    faces = {b: bones[b].faces for b in BONES}
    thickness, cart_report = cartilage.build_cartilage(
        verts, faces, articulations, bandwidth_mm=params.grnn_bandwidth_mm, max_thickness_mm=params.max_thickness_mm
    )
    thickness = {b: thickness.get(b, np.zeros(len(verts[b]))) for b in BONES}
    thickness["ulna"], tfcc_report = tfcc_thickness(
        bones, thickness, coverage[TFCC], params.grnn_bandwidth_mm, params.tfc_disc_mm
    )
    bones = _osteotomy(bones, params.ulnar_osteotomy_mm)  # the ulna moved with its layer, after it is made
    summary = _articulation_summary(cart_report["cartilage"]["articulations"])
    _check_joint_spaces(name, summary["joint_space_mm"])
    lap("cartilage")
    bundles, membrane = _ligaments(bones, sites, params)
    lap("ligaments")
    law = contact_law.fit_contact_law()
    lap("contact_law")
    displaced, s_pts, s_nrm, s_area, s_h, s_off = _contact_samples(bones, thickness, coverage, params)
    grids = {}
    for b in GRID_BONES:
        f = bones[b].faces[bones[b].solid[bones[b].faces].all(axis=1)]
        grids[b] = sdf.signed_distance_grid(
            displaced[b], f, spacing_mm=params.grid_spacing_mm, margin_mm=params.grid_margin_mm
        )
    s_pts, seated = _seat_samples(s_pts, s_nrm, s_off, grids)
    lap("grids")
    masses = [
        mass.mass_properties(*_solid(bones[b])) if bones[b].solid.any() else (0.0, np.zeros(3), np.zeros((3, 3)))
        for b in BONES
    ]
    centroids = [
        mass.mass_properties(*_solid(bones[b], part=0))[1] if bones[b].part.any() else m[1]
        for b, m in zip(BONES, masses)
    ]  # a body of one bone: its centre of mass
    lap("mass")
    bar.close()

    empty = np.zeros((0, 0, 0), np.float32)
    grid_list = [grids.get(b) for b in BONES]
    ref_len = np.array(
        [next((bd.reference_length_mm for k2, _, _, bd in bundles if k2 == k), np.nan) for k in range(len(LIGAMENTS))]
    )
    along = membrane.connector_kind == 0
    ref_len[RSC_INDEX] = float(np.sum(membrane.reference_length_mm[along]) / membrane.shape[1])  # mean chain length
    membrane_bone = np.full(len(membrane.nodes), -1, np.int64)
    membrane_bone[membrane.radius_nodes] = BONES.index("radius")
    membrane_bone[membrane.capitate_nodes] = BONES.index("capitate")

    report = {
        "name": name,
        "build_seconds": round(sum(timings.values()), 2),
        "timings_s": timings,
        "morph_error_mm": morph_report,
        "fibres": {ALL_LIGAMENTS[k].name: int(len(bd.origin)) for k, _, _, bd in bundles}
        | {"RSC": int(len(membrane.connectors))},
        "reference_length_mm": {n: round(float(x), 3) for n, x in zip(LIGAMENT_NAMES, ref_len)},
        "contact_law_r2": round(float(law.r2), 5),
        "sites_relocated": relocated,
        **summary,
        "contact_samples": {p: int(s_off[i + 1] - s_off[i]) for i, p in enumerate(PAIRS)},
        "contact_seating_mm": round(seated, 4),
        **cart_report,
        "tfcc_thickness_mm": tfcc_report,
        "ulnar_variance_mm": variance if variance is None else variance | {"osteotomy_mm": params.ulnar_osteotomy_mm},
    }
    return Model(
        name=name,
        source_hash=digest or source_hash(name, bones, params),
        vertices=np.vstack([bones[b].vertices for b in BONES]),
        vertex_offsets=offsets([len(bones[b].vertices) for b in BONES]),
        faces=np.vstack([bones[b].faces for b in BONES]).astype(np.int64),
        face_offsets=offsets([len(bones[b].faces) for b in BONES]),
        vertex_part=np.concatenate([bones[b].part for b in BONES]).astype(np.int64),
        thickness=np.concatenate([thickness[b] for b in BONES]),
        mass=np.array([m[0] for m in masses]),
        com=np.array([m[1] for m in masses]),
        inertia=np.array([m[2] for m in masses]),
        centroid=np.array(centroids),
        grid_origin=np.array([g.origin if g else np.zeros(3) for g in grid_list]),
        grid_spacing=np.array([g.spacing_mm if g else 0.0 for g in grid_list]),
        grid_shape=np.array([g.values.shape if g else (0, 0, 0) for g in grid_list], dtype=np.int64),
        grid_values=np.concatenate([(g.values if g else empty).ravel() for g in grid_list]),
        grid_offsets=offsets([(g.values if g else empty).size for g in grid_list]),
        sample_points=s_pts,
        sample_normals=s_nrm,
        sample_area=s_area,
        sample_thickness=s_h,
        sample_offsets=s_off,
        contact_law=law.law.as_array(),
        fibre_ligament=np.concatenate([np.full(len(bd.origin), k) for k, _, _, bd in bundles]).astype(np.int64),
        fibre_bones=np.concatenate(
            [np.tile([BONES.index(o), BONES.index(i)], (len(bd.origin), 1)) for _, o, i, bd in bundles]
        ).astype(np.int64),
        fibre_origin=np.vstack([bd.origin for *_, bd in bundles]),
        fibre_insertion=np.vstack([bd.insertion for *_, bd in bundles]),
        reference_length=ref_len,
        membrane_nodes=membrane.nodes,
        membrane_bone=membrane_bone,
        membrane_connectors=membrane.connectors.astype(np.int64),
        membrane_kind=membrane.connector_kind.astype(np.int64),
        membrane_length=membrane.reference_length_mm,
        report=report,
    )


def _articulation_summary(articulations: dict) -> dict:
    """Per articulation (`PAIRS` names): cartilage thickness over both layers and the joint space (mm)."""
    names = {"-".join(read_annotation_data()["cartilage"][art]["bones"]): art for art in PAIRS}
    thickness, space, overclosure = {}, {}, {}
    for key, art in articulations.items():
        sides = [v for v in art["thickness_mm"].values() if v]
        thickness[names[key]] = {
            "min": min(v["min"] for v in sides),
            "mean": round(float(np.mean([v["mean"] for v in sides])), 4),
            "max": max(v["max"] for v in sides),
        }
        space[names[key]] = art["joint_space_mm"]
        overclosure[names[key]] = art["overclosure_after_mm"]
    return {"cartilage_thickness_mm": thickness, "joint_space_mm": space, "overclosure_mm": overclosure}


def _check_joint_spaces(name: str, spaces: dict) -> None:
    """BuildError unless every articulation's neutral joint space (mm) is within `JOINT_SPACE_MM`."""
    bad = {
        art: gap
        for art, gap in spaces.items()
        if gap is None or not JOINT_SPACE_MM[art][0] <= gap <= JOINT_SPACE_MM[art][1]
    }
    if bad:
        listed = "; ".join(
            f"{art} {'none' if gap is None else f'{gap:.2f} mm'} (plausible "
            f"{JOINT_SPACE_MM[art][0]:g}–{JOINT_SPACE_MM[art][1]:g} mm)"
            for art, gap in bad.items()
        )
        raise BuildError(
            f"participant {name!r}: implausible joint spaces in the neutral pose: {listed}. The bones do not sit "
            f'as the template\'s do: check `side` in participant.toml (right-hand meshes declared "left" are '
            f"mirrored, and the reverse), and that the meshes are in the RCS, mm, neutral pose."
        )


def _solid(bone, part: int | None = None):
    """(vertices, faces) of the bone's closed surface (of one of its parts, if given)."""
    keep = bone.solid if part is None else bone.solid & (bone.part == part)
    f = bone.faces[keep[bone.faces].all(axis=1)]
    return bone.vertices, f
