"""Author the template annotations (`wrist_env/anatomy/data/annotations.json`).

Each ligament site is placed on the template bones (RCS: x volar, y proximal,
z radial) by an anatomical rule quoted from the descriptions the preprint
cites (Table 2): Berger 2001 (SLIL regions, RSC, LRL), Nagao 2005 (SRL, DRC,
UL), Mizuseki 1989 (DRC), Ringler 2013 (RCL), Apergis 2013 (SCL), Moritomo
2013 (UCL); Berger 2001 and Garcia-Elias 2017 for the fixed TC and TH; Garcia-Elias 1989,
Nanno 2006 and Bettinger 1999 for the radial column's TZC_p, TZC_d and STT; Ritt 1996 for the
hamate's capitohamate CH_deep, CH_d and CH_p. A rule
picks the extreme vertex of a bone region along an anatomical direction; the patch is the bone surface within `radius_mm` of it.
Cartilage coverage is the part of each bone facing its partner within a gap.

The output is plain data, reviewed in `experiments/figures/template_annotations.png`
(`wrist-bench figure annotations`). Run: `python experiments/authoring/make_annotations.py`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from wrist_env.anatomy import midcarpal
from wrist_env.anatomy.template import JOINT_SPACE_MM, load_template, oriented_parts
from wrist_env.ligaments import LIGAMENTS

DATA = Path(__file__).resolve().parents[2] / "wrist_env" / "anatomy" / "data"
OUT = DATA / "annotations.json"
SEAT = DATA / midcarpal.SEAT_FILE


def unit(*v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def extreme(points, direction, where=None):
    """The point of `points` (restricted to `where`) furthest along `direction`."""
    idx = np.arange(len(points)) if where is None else np.flatnonzero(where)
    return points[idx[np.argmax(points[idx] @ unit(*direction))]]


def patch_radius(bone: str, lig) -> float:
    """Site radius (mm): wider on the coarser forearm bones and for the RSC membrane and 7-fibre bundles."""
    if lig.name == "RSC":
        return 3.5
    if bone in ("radius", "ulna"):
        return 3.0
    return 2.5 if lig.fibres >= 7 else 2.0


def write_seat() -> None:
    """Fit the distal row's seating on the myo-sim bones and write it (`anatomy.midcarpal`)."""
    record = midcarpal.seat_record(oriented_parts()[0], JOINT_SPACE_MM)
    SEAT.write_text(json.dumps(record, indent=1) + "\n")
    print(f"wrote {SEAT}: facet gaps {record['facet_gaps_before_mm']} -> {record['facet_gaps_after_mm']} mm")


def main() -> None:
    write_seat()
    load_template.cache_clear()
    template = load_template()
    V = {b: template.parts[b].vertices for b in template.parts}  # rules read the bones one by one
    near = lambda a, b, gap: cKDTree(V[b]).query(V[a])[0] < gap  # noqa: E731
    s_sl, l_sl = near("scaphoid", "lunate", 3.0), near("lunate", "scaphoid", 3.0)
    distal_radius = V["radius"][:, 1] < 6.0
    distal_ulna = V["ulna"][:, 1] < V["ulna"][:, 1].min() + 8.0
    cap_waist = np.abs(V["capitate"][:, 1] - V["capitate"][:, 1].mean()) < 3.0
    lun_c, sca_c = V["lunate"].mean(axis=0), V["scaphoid"].mean(axis=0)

    site = {
        # Berger 2001: the SLIL is C-shaped, volar, proximal (membranous) and dorsal regions
        # spanning the rims of the scapholunate interval.
        "SLIL_v": (
            ("scaphoid", extreme(V["scaphoid"], (1, 0, 0), s_sl)),
            ("lunate", extreme(V["lunate"], (1, 0, 0), l_sl)),
        ),
        "SLIL_p": (
            ("scaphoid", extreme(V["scaphoid"], (0, 1, 0), s_sl)),
            ("lunate", extreme(V["lunate"], (0, 1, 0), l_sl)),
        ),
        "SLIL_d": (
            ("scaphoid", extreme(V["scaphoid"], (-1, 0, 0), s_sl)),
            ("lunate", extreme(V["lunate"], (-1, 0, 0), l_sl)),
        ),
        # Berger 2001: RSC from the volar radial styloid, volar to the scaphoid waist, to the
        # volar capitate waist.
        "RSC": (
            ("radius", extreme(V["radius"], (1, 0, 1), V["radius"][:, 1] < -2.0)),
            ("capitate", extreme(V["capitate"], (1, 0, 0.3), cap_waist)),
        ),
        # Berger 2001, Nagao 2005: LRL from the volar rim of the scaphoid fossa, ulnar to the
        # RSC, to the volar-radial horn of the lunate.
        "LRL": (
            (
                "radius",
                extreme(V["radius"], (1, -0.2, 0), distal_radius & (V["radius"][:, 2] > 1) & (V["radius"][:, 2] < 6)),
            ),
            ("lunate", extreme(V["lunate"], (1, 0, 0.6))),
        ),
        # Nagao 2005: SRL from the volar rim of the lunate fossa to the volar-ulnar lunate.
        "SRL": (
            (
                "radius",
                extreme(
                    V["radius"], (1, -0.2, 0), distal_radius & (V["radius"][:, 2] < -3) & (V["radius"][:, 2] > -10)
                ),
            ),
            ("lunate", extreme(V["lunate"], (1, 0.5, -0.3), V["lunate"][:, 1] > lun_c[1])),
        ),
        # Nagao 2005, Mizuseki 1989: DRC from the dorsal rim of the radius (Lister's region)
        # to the dorsal lunate (with the distal row and triquetrum: on to the dorsal tubercle
        # of the triquetrum, which moves with the lunate body; see `part` below).
        "DRC": (
            ("radius", extreme(V["radius"], (-1, -0.2, 0), distal_radius & (np.abs(V["radius"][:, 2]) < 5))),
            ("lunate", extreme(V["lunate"], (-1, 0, 0))),
        ),
        # Ringler 2013: RCL from the tip of the radial styloid to the radial scaphoid waist.
        "RCL": (
            ("radius", extreme(V["radius"], (0, -1, 1.2), distal_radius)),
            ("scaphoid", extreme(V["scaphoid"], (0, 0, 1), np.abs(V["scaphoid"][:, 1] - sca_c[1]) < 3)),
        ),
        # Apergis 2013: SCL from the volar-ulnar distal pole of the scaphoid to the volar-radial capitate waist.
        "SCL": (
            ("scaphoid", extreme(V["scaphoid"], (1, -1, -0.5))),
            ("capitate", extreme(V["capitate"], (0.6, 0, 1), cap_waist)),
        ),
        # Moritomo 2013: UCL from the ulnar fovea/styloid base, volar to the lunate, to the volar capitate.
        "UCL": (
            ("ulna", extreme(V["ulna"], (1, -0.3, 0), distal_ulna)),
            ("capitate", extreme(V["capitate"], (1, 0, -0.5), cap_waist)),
        ),
        # Nagao 2005: UL from the volar ulnar head/TFCC to the volar-ulnar lunate.
        "UL": (("ulna", extreme(V["ulna"], (1, -0.5, 0.5), distal_ulna)), ("lunate", extreme(V["lunate"], (1, 0, -1)))),
    }
    ligaments = {}
    for lig in LIGAMENTS:
        (ob, oc), (ib, ic) = site[lig.name]
        ligaments[lig.name] = {
            "origin": {"bone": ob, "centre_mm": np.round(oc, 3).tolist(), "radius_mm": patch_radius(ob, lig)},
            "insertion": {"bone": ib, "centre_mm": np.round(ic, 3).tolist(), "radius_mm": patch_radius(ib, lig)},
        }
    # Mizuseki 1989: the DRC's main insertion is the dorsal tubercle of the triquetrum.
    drc = ligaments["DRC"]["insertion"]
    ligaments["DRC"]["insertion"] = {
        "bone": "lunate",
        "part": "triquetrum",
        "centre_mm": np.round(extreme(V["triquetrum"], (-1, 0, 0)), 3).tolist(),
        "radius_mm": drc["radius_mm"],
        "without_part": drc,
    }
    # Berger 2001, Garcia-Elias 2017: the ulnar arm of the palmar arcuate ligament, from the
    # palmar-distal triquetrum to the palmar capitate neck (TC, beside the UCL's insertion) and
    # to the palmar hamate body proximal to its hook (TH). Fixed ligaments of the distal row.
    tri = {
        "bone": "lunate",
        "part": "triquetrum",
        "radius_mm": 2.0,
        "centre_mm": np.round(extreme(V["triquetrum"], (1, -0.6, 0.4)), 3).tolist(),
    }
    hamate_body = V["hamate"][:, 1] > V["hamate"][:, 1].mean()
    ligaments["TC"] = {
        "origin": tri,
        "insertion": {
            "bone": "capitate",
            "radius_mm": 2.0,
            "centre_mm": np.round(extreme(V["capitate"], (1, 0, -0.5), cap_waist), 3).tolist(),
        },
    }
    ligaments["TH"] = {
        "origin": tri,
        "insertion": {
            "bone": "hamate",
            "radius_mm": 2.0,
            "centre_mm": np.round(extreme(V["hamate"], (1, 0.3, 0.3), hamate_body), 3).tolist(),
        },
    }
    # The radial column (trapezium + trapezoid, its own body): the trapezoid is bound to the
    # capitate by dorsal and palmar trapezocapitate ligaments spanning the rims of their joint
    # (Garcia-Elias 1989, J Hand Surg Am 14:277; Nanno 2006, J Hand Surg Am 31:1160), and the
    # column to the scaphoid by the palmar STT ligament, from the scaphoid tubercle to the palmar
    # trapezium proximal to its ridge (Bettinger 1999, J Hand Surg Am 24:786).
    tz_c, c_tz = near("trapezoid", "capitate", 2.5), near("capitate", "trapezoid", 2.5)
    for name, direction in (("TZC_p", (1, 0, 0)), ("TZC_d", (-1, 0, 0))):
        ligaments[name] = {
            "origin": {
                "bone": "trapezium",
                "part": "trapezoid",
                "radius_mm": 2.0,
                "centre_mm": np.round(extreme(V["trapezoid"], direction, tz_c), 3).tolist(),
            },
            "insertion": {
                "bone": "capitate",
                "radius_mm": 2.0,
                "centre_mm": np.round(extreme(V["capitate"], direction, c_tz), 3).tolist(),
            },
        }
    # The hamate (its own body, issue 54): bound to the capitate by the capitohamate interosseous
    # ligament's three regions (Ritt, Berger, Bishop & An 1996, J Hand Surg Br 21:451): dorsal and
    # palmar bands spanning the dorsal and palmar edges of the joint, and the deep band between the
    # facing surfaces at the joint's distal end, midway dorsopalmarly. Each band runs across the
    # joint: its capitate end is the capitate's extreme along the same direction within 2 mm of its
    # hamate end proximodistally (and, for the deep band, dorsopalmarly).
    h_c, c_h = near("hamate", "capitate", 2.5), near("capitate", "hamate", 2.5)
    middle = np.abs(V["hamate"][:, 0] - V["hamate"][h_c, 0].mean()) < 2.0
    for name, direction, hamate_end in (
        ("CH_p", (1, 0, 0), extreme(V["hamate"], (1, 0, 0), h_c)),
        ("CH_d", (-1, 0, 0), extreme(V["hamate"], (-1, 0, 0), h_c)),
        ("CH_deep", (0, -1, 0), extreme(V["hamate"], (0, -1, 0), h_c & middle)),
    ):
        axes = [1] if name != "CH_deep" else [0, 1]
        level = c_h & (np.abs(V["capitate"][:, axes] - hamate_end[axes]) < 2.0).all(axis=1)
        ligaments[name] = {
            "origin": {"bone": "hamate", "radius_mm": 2.0, "centre_mm": np.round(hamate_end, 3).tolist()},
            "insertion": {
                "bone": "capitate",
                "radius_mm": 2.0,
                "centre_mm": np.round(extreme(V["capitate"], direction, level), 3).tolist(),
            },
        }
    ligaments["STT"] = {
        "origin": {
            "bone": "scaphoid",
            "radius_mm": 2.0,
            "centre_mm": np.round(extreme(V["scaphoid"], (1, -1, 1)), 3).tolist(),
        },
        "insertion": {
            "bone": "trapezium",
            "radius_mm": 2.0,
            "centre_mm": np.round(extreme(V["trapezium"], (1, 0.5, 0)), 3).tolist(),
        },
    }
    # Articulations are between rigid bodies; the radial column
    # meets the scaphoid's distal pole (the STT joint) and the capitate (the trapezoid–capitate
    # joint) as articulations of its own.
    cartilage = {
        "radioscaphoid": {"bones": ["radius", "scaphoid"], "max_gap_mm": 2.5},
        "radiolunate": {"bones": ["radius", "lunate"], "max_gap_mm": 2.5},
        "scapholunate": {"bones": ["scaphoid", "lunate"], "max_gap_mm": 2.5},
        "scaphocapitate": {"bones": ["scaphoid", "capitate"], "max_gap_mm": 3.0},
        "lunocapitate": {"bones": ["lunate", "capitate"], "max_gap_mm": 2.5},
        "scaphotrapezial": {"bones": ["scaphoid", "trapezium"], "max_gap_mm": 3.0},
        "trapeziocapitate": {"bones": ["trapezium", "capitate"], "max_gap_mm": 2.5},
        # the TFCC fills the ulnocarpal space: the lunate lies 5.8-6.6 mm and the triquetrum 8.8-10.1 mm
        # from the template's ulnar head (issue 33); the disc covers the head's distal face
        "ulnocarpal": {"bones": ["ulna", "lunate"], "max_gap_mm": 10.5},
        # the hamate, its own body (issue 54): against the capitate, and the lunate body on it (the
        # triquetrum's helicoid facet; the lunate's, where a type II lunate reaches it)
        "capitohamate": {"bones": ["hamate", "capitate"], "max_gap_mm": 2.5},
        "triquetrohamate": {"bones": ["lunate", "hamate"], "max_gap_mm": 2.5},
    }
    data = {
        "about": "wrist-env template annotations in the template RCS (mm); written by experiments/authoring/make_annotations.py",
        "cartilage": cartilage,
        "ligaments": ligaments,
    }
    OUT.write_text(json.dumps(data, indent=2) + "\n")
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
