"""The rebuilt fossae's geometry against published distal-radius morphometry (issue 54, step 7).

myo-sim's radius is coarse, so the package builds the scaphoid and lunate fossae itself
(`anatomy.radius_cap`: the offset envelope of the swept proximal row). This probe measures what that
construction gives, on each participant's bones in the RCS (mm; x volar, y proximal, z radial), as a
radiologist or an anatomist would on a radius:

- **articular surface**: the rebuilt solid's (`BoneSurface.solid`) faces whose outward normal's distal
  (−y) component exceeds `TOP_FACING` (its heightfield top; the extrusion's walls and base are left
  out); a vertex's area is a third of its top faces' (`vertex_areas`).
- **fossa area** (mm²): the area of the articular vertices each articulation's cartilage covers, by the
  annotations' rule (`annotations.facing_within` with the articulation's `max_gap_mm`: within that
  bone-to-bone gap of the scaphoid or lunate and facing it); a vertex both cover goes to the nearer
  bone. And the scaphoid/lunate ratio.
- **radius of curvature** (mm) of each fossa: least-squares (Kåsa) circles through the fossa's points
  in a 1 mm slab through its area centroid: sagittal (the x–y plane, a slab in z) and coronal (the
  z–y plane, a slab in x); and a least-squares sphere through the whole fossa (with its RMS
  residual). The capitate head's circles in the same planes (its proximal-facing vertices within
  `CAPITATE_HEAD_MM` of its most proximal one) give the capitate/lunate-fossa ratios Hawkins-Rivers
  et al. measured on MRI; the lunate's own proximal surface's circles (`LUNATE_SURFACE_MM`) show
  what the lunate fossa's curvature comes from.
- **the interfossal ridge**: in 1 mm sagittal bands (slabs in x) every `RIDGE_STEP_MM` across both
  fossae, the articular surface's profile y(z) (median y in `BIN_MM` bins of z); each fossa's floor
  is the profile's deepest (most proximal) point over that fossa's z-range in the band, the ridge the
  profile's most distal point between the two floors; its height above each floor and above the
  chord joining them (its prominence, free of the surface's coronal slope) (mm, + distal).
- **radial inclination** (deg): the line from the radial styloid's tip (the most distal vertex of
  myo-sim's radius, `ulnar_variance.radius_bone`, radial of the origin) to the radius' ulnar corner
  (`ulnar_variance.ulnar_corner`, issue 54's corner rule), against the RCS's z axis (perpendicular
  to the shaft) in the coronal projection, + where the tip is distal; and the rebuilt surface's own:
  the line joining the most distal points within `RIM_BAND_MM` of the radial and the ulnar end of
  its coronal section (a 1 mm slab in x) through its area centroid.
- **volar tilt** (deg): the line joining the most distal points within `RIM_BAND_MM` of the dorsal
  and the volar end of a fossa's sagittal section (a 1 mm slab in z through its area centroid),
  against the x axis, + where the volar rim is proximal. The lunate fossa's is the radiographic one
  (its rims are the lateral view's); and the same on myo-sim's radius' distal end (its vertices
  less than `ulnar_variance.RIM_Y_MM` proximal of the origin, a slab of ±`MYOSIM_SLAB_MM`).
- **dimensions** (mm): the extents of the articular surface and of each fossa along x (dorsopalmar)
  and z (radioulnar); and the styloid tip to ulnar corner distance along z. And the scaphoid–lunate
  bone gap along x (`row_gaps`), which shapes the ridge.

Run: `python experiments/research/fossa_morphometry.py [P1 P2 P3] [--template]` (a few seconds each;
reads the bones, builds no model). Prints Markdown tables; published values are in `PUBLISHED` and
in docs/model.md.
"""

from __future__ import annotations

import sys

import numpy as np

from wrist_env.anatomy.template import vertex_areas

RIM_BAND_MM = 2.0
"""A rim: the surface's points within this of its least or greatest coordinate along the axis (mm)."""
SLAB_MM = 0.5
"""Half the thickness of a section's slab (mm)."""
RIDGE_STEP_MM = 2.0
"""The spacing of the ridge's sagittal bands along x (mm)."""
BIN_MM = 0.5
"""The z-bins of a band's profile (mm)."""
TOP_FACING = 0.2
"""The articular surface: the rebuilt solid's faces whose outward normal's distal component (−y) exceeds
this (its heightfield top; the extrusion's walls are near vertical, its base faces proximal)."""
FACING = 0.5
"""The capitate's head: its vertices whose outward normal's proximal component (+y) exceeds this."""
MYOSIM_SLAB_MM = 1.5
"""Half the thickness of a section of myo-sim's radius (mm): its distal end is subdivided to 1.5 mm edges."""
CAPITATE_HEAD_MM = 5.0
"""The capitate's head: its proximal-facing vertices within this of its most proximal one (mm, along y)."""
LUNATE_SURFACE_MM = 4.0
"""The lunate's radial articular surface: its proximal-facing vertices within this of its most proximal one (mm)."""
SL_GAP_X_MM = (-8.0, -4.0, 0.0, 4.0, 8.0)
"""Where along x (mm, + volar) the scaphoid–lunate bone gap is read (`row_gaps`)."""

PUBLISHED = {
    "scaphoid/lunate area": "0.89 (47 % / 53 %; J Hand Surg Am 1996;21:567, 50 dry radii)",
    "lunate fossa dorsopalmar": "19 ± 3 mm (Andermahr 2006, 48 CT)",
    "capitate/lunate fossa R, coronal": "0.37 ± 0.10 (Hawkins-Rivers, MRI, 20)",
    "capitate/lunate fossa R, sagittal": "0.57 ± 0.10 (Hawkins-Rivers, MRI, 20)",
    "radial inclination": "24° (19–29; Schuind 1992, 120); 23° (15–35; Schmitt & Lanz)",
    "volar tilt": "15.4 ± 4.3° (Bilgin 2023, 981); ~11° (textbook)",
}


def vertex_normals(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Unit area-weighted vertex normals (n, 3) of a mesh whose faces wind outward."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    fn = np.cross(b - a, c - a)  # length twice the area: area-weighted
    out = np.zeros_like(v, dtype=float)
    for k in range(3):
        np.add.at(out, f[:, k], fn)
    return out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-12)


def patch_area(v: np.ndarray, f: np.ndarray, mask: np.ndarray) -> float:
    """Area (mm²) of the vertices in `mask` (n,) by `vertex_areas`."""
    return float(vertex_areas(v, f)[mask].sum())


def _fit_ball(p: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Least-squares (Kåsa) circle or sphere through points `p` (n, d): centre (d,), radius, RMS radial
    residual."""
    p = np.asarray(p, float)
    A = np.column_stack([2.0 * p, np.ones(len(p))])
    sol = np.linalg.lstsq(A, (p**2).sum(axis=1), rcond=None)[0]
    centre = sol[:-1]
    radius = float(np.sqrt(sol[-1] + centre @ centre))
    rms = float(np.sqrt(np.mean((np.linalg.norm(p - centre, axis=1) - radius) ** 2)))
    return centre, radius, rms


def fit_circle(p: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Least-squares circle through 2-D points `p` (n, 2): centre (2,), radius, RMS radial residual."""
    return _fit_ball(p)


def fit_sphere(p: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Least-squares sphere through points `p` (n, 3): centre (3,), radius, RMS radial residual."""
    return _fit_ball(p)


def section_radii(p: np.ndarray, through: np.ndarray, slab_mm: float = SLAB_MM) -> dict:
    """Radii of curvature (mm) of surface points `p` (n, 3) in the sagittal and coronal sections through
    `through` (3,): circles fitted to the points within `slab_mm` of it in z (sagittal: x–y) and in x
    (coronal: z–y). NaN where a section holds fewer than 5 points."""
    out = {}
    for name, cut, plane in (("sagittal", 2, [0, 1]), ("coronal", 0, [2, 1])):
        inside = np.abs(p[:, cut] - through[cut]) <= slab_mm
        out[name] = fit_circle(p[inside][:, plane])[1] if inside.sum() >= 5 else float("nan")
    return out


def rim_slope(p: np.ndarray, axis: int, band_mm: float = RIM_BAND_MM, through=None, slab_mm: float = SLAB_MM) -> float:
    """Slope (deg) of the line joining the most distal (least y) points of the surface `p` (n, 3) within
    `band_mm` of its least and of its greatest coordinate along `axis` (0: x, 2: z), projected on that
    axis and y: atan2(y_high − y_low, c_high − c_low), + where the high rim is the more proximal. With
    `through` (3,), only the points within `slab_mm` of it across the section (in z for axis x, in x for
    axis z): the section's rims."""
    if through is not None:
        across = 2 if axis == 0 else 0
        p = p[np.abs(p[:, across] - through[across]) <= slab_mm]
    c = p[:, axis]
    low = p[c <= c.min() + band_mm]
    high = p[c >= c.max() - band_mm]
    a, b = low[np.argmin(low[:, 1])], high[np.argmin(high[:, 1])]
    return float(np.degrees(np.arctan2(b[1] - a[1], b[axis] - a[axis])))


def inclination(tip: np.ndarray, corner: np.ndarray) -> float:
    """Radial inclination (deg): the line from the radial styloid's `tip` (3,) to the ulnar `corner` (3,)
    against the z axis in the coronal (z–y) projection, + where the tip is distal of the corner."""
    return float(np.degrees(np.arctan2(corner[1] - tip[1], tip[2] - corner[2])))


def ridge_profile(
    p: np.ndarray,
    scaphoid: np.ndarray,
    lunate: np.ndarray,
    xs,
    slab_mm: float = SLAB_MM,
    bin_mm: float = BIN_MM,
) -> list[dict]:
    """The interfossal ridge in sagittal bands: for each x in `xs`, the articular surface `p` (n, 3)
    within `slab_mm` of it, its profile y(z) (median y per `bin_mm` bin of z), each fossa's floor (the
    profile's greatest y over the z-range of that fossa's points in the band: `scaphoid`, `lunate`, (n,)
    masks) and the ridge (the profile's least y between the floors): x, the ridge's z, its height above
    each floor and above the chord joining the floors (its prominence, free of the surface's coronal
    slope) (mm, + distal of it). Bands without both fossae are left out."""
    out = []
    for x in xs:
        band = np.abs(p[:, 0] - x) <= slab_mm
        s, lu = band & scaphoid, band & lunate
        if s.sum() < 3 or lu.sum() < 3:
            continue
        z = p[band, 2]
        edges = np.arange(z.min(), z.max() + bin_mm, bin_mm)
        which = np.digitize(z, edges)
        centres, ys = [], []
        for k in np.unique(which):
            centres.append(z[which == k].mean())
            ys.append(np.median(p[band, 1][which == k]))
        centres, ys = np.array(centres), np.array(ys)

        def floor(mask):
            zr = p[mask, 2]
            inside = (centres >= zr.min()) & (centres <= zr.max())
            k = np.flatnonzero(inside)[np.argmax(ys[inside])]
            return centres[k], ys[k]

        (zs, ys_floor), (zl, yl_floor) = floor(s), floor(lu)
        between = (centres >= min(zs, zl)) & (centres <= max(zs, zl))
        k = np.flatnonzero(between)[np.argmin(ys[between])]
        chord = ys_floor if zs == zl else ys_floor + (yl_floor - ys_floor) * (centres[k] - zs) / (zl - zs)
        out.append(
            {
                "x": float(x),
                "ridge_z": float(centres[k]),
                "above_scaphoid": float(ys_floor - ys[k]),
                "above_lunate": float(yl_floor - ys[k]),
                "above_chord": float(chord - ys[k]),
            }
        )
    return out


def fossa_masks(bones: dict) -> tuple[np.ndarray, np.ndarray]:
    """The radius vertices of the scaphoid and lunate fossae (masks (n,)), by the annotations' cartilage
    rule on these bones; a vertex both cover goes to the nearer bone."""
    import igl

    from wrist_env.anatomy.annotations import facing_within, read_annotation_data

    data = read_annotation_data()["cartilage"]
    radius = bones["radius"]
    surface = radius.trimesh()
    masks, dists = [], []
    for art, bone in (("radioscaphoid", "scaphoid"), ("radiolunate", "lunate")):
        other = bones[bone].trimesh(solid_only=True)
        f = other.faces.astype(np.int64)
        masks.append(
            facing_within(surface.vertices, surface.vertex_normals, other.vertices, f, data[art]["max_gap_mm"])
            & radius.solid
        )
        d2 = igl.point_mesh_squared_distance(np.ascontiguousarray(surface.vertices, float), other.vertices, f)[0]
        dists.append(d2)
    both = masks[0] & masks[1]
    s = masks[0] & ~(both & (dists[0] > dists[1]))
    lu = masks[1] & ~(both & (dists[1] >= dists[0]))
    return s, lu


def proximal_radii(bones: dict, bone: str, depth_mm: float) -> dict:
    """A bone's proximal articular surface's radii of curvature (mm) in the sagittal and coronal sections
    through its centroid: the principal bone's vertices facing proximal (normal·y > `FACING`) within
    `depth_mm` of its most proximal one (the capitate's head; the lunate's radial surface)."""
    from wrist_env.model import BODY_PARTS

    body = bones[bone]
    keep = body.part == BODY_PARTS[bone].index(bone)
    v, f = body.vertices, body.faces[keep[body.faces].all(axis=1)]
    n = vertex_normals(v, f)
    head = keep & (n[:, 1] > FACING) & (v[:, 1] >= v[keep, 1].max() - depth_mm)
    return section_radii(v[head], v[head].mean(axis=0))


def row_gaps(bones: dict, xs=SL_GAP_X_MM) -> list[float]:
    """The scaphoid–lunate bone gap (mm) in 2 mm bands of x around each of `xs`: the least distance from
    a scaphoid vertex in the band to the lunate's vertices (NaN where the band holds none)."""
    from scipy.spatial import cKDTree

    s, lu = bones["scaphoid"], bones["lunate"]
    sv, lv = s.vertices[s.part == 0], lu.vertices[lu.part == 0]
    d = cKDTree(lv).query(sv)[0]
    return [
        float(d[np.abs(sv[:, 0] - x) < 1.0].min()) if (np.abs(sv[:, 0] - x) < 1.0).any() else float("nan") for x in xs
    ]


def measure(bones: dict) -> dict:
    """Every quantity of the module docstring on one participant's bones (name -> `BoneSurface`, RCS mm)."""
    from wrist_env.anatomy.ulnar_variance import RIM_Y_MM, radius_bone, ulnar_corner

    radius = bones["radius"]
    v, f = np.asarray(radius.vertices, float), np.asarray(radius.faces)
    solid_faces = f[radius.solid[f].all(axis=1)]
    a, b, c = v[solid_faces[:, 0]], v[solid_faces[:, 1]], v[solid_faces[:, 2]]
    normal = np.cross(b - a, c - a)
    top_faces = solid_faces[-normal[:, 1] > TOP_FACING * np.linalg.norm(normal, axis=1)]
    areas = vertex_areas(v, top_faces)  # the articular surface's own: no wall or base face counts
    top = areas > 0
    s, lu = fossa_masks(bones)
    s, lu = s & top, lu & top
    out = {"area_scaphoid": float(areas[s].sum()), "area_lunate": float(areas[lu].sum())}
    out["area_ratio"] = out["area_scaphoid"] / out["area_lunate"]
    out["area_top"] = float(areas.sum())
    for name, mask in (("scaphoid", s), ("lunate", lu)):
        p = v[mask]
        centroid = (p * areas[mask, None]).sum(axis=0) / areas[mask].sum()
        sec = section_radii(p, centroid)
        out[f"R_{name}_sagittal"], out[f"R_{name}_coronal"] = sec["sagittal"], sec["coronal"]
        out[f"R_{name}_sphere"], out[f"rms_{name}_sphere"] = fit_sphere(p)[1:]
        out[f"tilt_{name}"] = rim_slope(p, 0, through=centroid)
        out[f"centroid_{name}"] = centroid
        out[f"dp_{name}"] = float(np.ptp(p[:, 0]))
        out[f"ru_{name}"] = float(np.ptp(p[:, 2]))
    head = proximal_radii(bones, "capitate", CAPITATE_HEAD_MM)
    lunate = proximal_radii(bones, "lunate", LUNATE_SURFACE_MM)
    out["R_lunate_bone_sagittal"], out["R_lunate_bone_coronal"] = lunate["sagittal"], lunate["coronal"]
    out["sl_gaps"] = tuple(row_gaps(bones))
    out["capitate_lunate_coronal"] = head["coronal"] / out["R_lunate_coronal"]
    out["capitate_lunate_sagittal"] = head["sagittal"] / out["R_lunate_sagittal"]
    out["R_capitate_coronal"], out["R_capitate_sagittal"] = head["coronal"], head["sagittal"]

    articular = v[top]
    bone = radius_bone(radius)
    radial = bone[bone[:, 2] > 0]
    tip = radial[np.argmin(radial[:, 1])]
    corner = ulnar_corner(bone)
    out["inclination"] = inclination(tip, corner)
    centre = (articular * areas[top, None]).sum(axis=0) / areas[top].sum()
    out["inclination_surface"] = -rim_slope(articular, 2, through=centre)
    distal_end = bone[bone[:, 1] < RIM_Y_MM]
    out["tilt_myosim"] = rim_slope(distal_end, 0, through=out["centroid_lunate"], slab_mm=MYOSIM_SLAB_MM)
    out["dp_articular"] = float(np.ptp(articular[:, 0]))
    out["ru_articular"] = float(np.ptp(articular[:, 2]))
    out["ru_styloid_corner"] = float(tip[2] - corner[2])
    lo = max(v[s, 0].min(), v[lu, 0].min())
    hi = min(v[s, 0].max(), v[lu, 0].max())
    ridge = ridge_profile(articular, s[top], lu[top], np.arange(np.ceil(lo), hi, RIDGE_STEP_MM))
    out["ridge"] = ridge
    prominence = [r["above_chord"] for r in ridge] or [float("nan")]
    k = int(np.argmax(prominence))
    out["ridge_prominence"], out["ridge_prominence_x"] = float(prominence[k]), ridge[k]["x"] if ridge else float("nan")
    return out


ROWS = (
    ("scaphoid fossa area (mm²)", "area_scaphoid", "{:.0f}", None),
    ("lunate fossa area (mm²)", "area_lunate", "{:.0f}", None),
    ("scaphoid/lunate area", "area_ratio", "{:.2f}", "scaphoid/lunate area"),
    ("articular surface area (mm²)", "area_top", "{:.0f}", None),
    ("scaphoid fossa R sagittal (mm)", "R_scaphoid_sagittal", "{:.1f}", None),
    ("scaphoid fossa R coronal (mm)", "R_scaphoid_coronal", "{:.1f}", None),
    ("scaphoid fossa R sphere (rms) (mm)", ("R_scaphoid_sphere", "rms_scaphoid_sphere"), "{:.1f} ({:.2f})", None),
    ("lunate fossa R sagittal (mm)", "R_lunate_sagittal", "{:.1f}", None),
    ("lunate fossa R coronal (mm)", "R_lunate_coronal", "{:.1f}", None),
    ("lunate fossa R sphere (rms) (mm)", ("R_lunate_sphere", "rms_lunate_sphere"), "{:.1f} ({:.2f})", None),
    (
        "lunate's proximal surface R sagittal / coronal (mm)",
        ("R_lunate_bone_sagittal", "R_lunate_bone_coronal"),
        "{:.1f} / {:.1f}",
        None,
    ),
    ("capitate head R sagittal / coronal (mm)", ("R_capitate_sagittal", "R_capitate_coronal"), "{:.1f} / {:.1f}", None),
    ("capitate/lunate fossa R, coronal", "capitate_lunate_coronal", "{:.2f}", "capitate/lunate fossa R, coronal"),
    ("capitate/lunate fossa R, sagittal", "capitate_lunate_sagittal", "{:.2f}", "capitate/lunate fossa R, sagittal"),
    (
        "ridge, greatest prominence (mm) at x (mm)",
        ("ridge_prominence", "ridge_prominence_x"),
        "{:.2f} at {:+.0f}",
        None,
    ),
    ("radial inclination, styloid to corner (°)", "inclination", "{:.1f}", "radial inclination"),
    ("radial inclination, rebuilt surface's coronal section (°)", "inclination_surface", "{:.1f}", None),
    ("volar tilt, lunate fossa section (°)", "tilt_lunate", "{:.1f}", "volar tilt"),
    ("volar tilt, scaphoid fossa section (°)", "tilt_scaphoid", "{:.1f}", None),
    ("volar tilt, myo-sim's radius rims at the lunate fossa (°)", "tilt_myosim", "{:.1f}", None),
    ("articular surface dorsopalmar / radioulnar (mm)", ("dp_articular", "ru_articular"), "{:.1f} / {:.1f}", None),
    ("scaphoid fossa dorsopalmar / radioulnar (mm)", ("dp_scaphoid", "ru_scaphoid"), "{:.1f} / {:.1f}", None),
    (
        "lunate fossa dorsopalmar / radioulnar (mm)",
        ("dp_lunate", "ru_lunate"),
        "{:.1f} / {:.1f}",
        "lunate fossa dorsopalmar",
    ),
    ("styloid tip to ulnar corner, along z (mm)", "ru_styloid_corner", "{:.1f}", None),
    (
        "scaphoid–lunate bone gap at x = " + ", ".join(f"{x:+.0f}" for x in SL_GAP_X_MM) + " (mm)",
        "sl_gaps",
        " / ".join(["{:.1f}"] * len(SL_GAP_X_MM)),
        None,
    ),
)


def cell(result: dict, key, fmt: str) -> str:
    keys = key if isinstance(key, tuple) else (key,)
    values = [v for k in keys for v in (result[k] if isinstance(result[k], tuple) else (result[k],))]
    return fmt.format(*values)


def table(results: dict) -> str:
    names = list(results)
    lines = ["| quantity | " + " | ".join(names) + " | published |", "|---" * (len(names) + 2) + "|"]
    for label, key, fmt, pub in ROWS:
        row = [cell(results[n], key, fmt) for n in names]
        lines.append(f"| {label} | " + " | ".join(row) + f" | {PUBLISHED[pub] if pub else '—'} |")
    return "\n".join(lines)


def ridge_table(name: str, ridge: list[dict]) -> str:
    lines = [
        f"Ridge profile, {name} (sagittal bands 1 mm thick; heights mm, + distal; x + volar):",
        "",
        "| x (mm) | ridge z (mm) | above scaphoid floor | above lunate floor | above the floors' chord |",
        "|---|---|---|---|---|",
    ]
    lines += [
        f"| {r['x']:+.0f} | {r['ridge_z']:+.1f} | {r['above_scaphoid']:.2f} | {r['above_lunate']:.2f} "
        f"| {r['above_chord']:.2f} |"
        for r in ridge
    ]
    return "\n".join(lines)


def main(argv: list[str]) -> None:
    from wrist_env.builder.params import BuildParams
    from wrist_env.participants import registry

    names = [a for a in argv if not a.startswith("--")] or ["P1", "P2", "P3"]
    params = BuildParams()
    results = {}
    if "--template" in argv:
        from wrist_env.anatomy.template import load_template

        results["template"] = measure(load_template(*params.anatomy).bones)
    for name in names:
        results[name] = measure(registry.bones(name, params))
    print(table(results))
    for name, r in results.items():
        print()
        print(ridge_table(name, r["ridge"]))


if __name__ == "__main__":
    main(sys.argv[1:])
