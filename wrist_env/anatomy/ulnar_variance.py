"""Ulnar variance (issue 54): the corner rule that measures it, and the ulna's seat that sets it.

Ulnar variance is the level of the ulnar head's articular dome against that of the radius' ulnar
corner (the sigmoid notch's distal rim), along the radius' long axis: + where the ulna reaches further
distal (ulna plus; the adult mean +0.26 mm, Yoshioka 2007; adults measure about −4…+5 mm). Here the axis
is the RCS's y (the radius' long axis, + proximal), and the two levels are read off the meshes
(`ulnar_variance`, issue 54's step-0 rule):

- the radius' ulnar corner: among the radius' vertices less than `RIM_Y_MM` proximal of the RCS origin
  (its distal end), those within `BORDER_MM` of the most ulnar (least z) one are its ulnar border; the
  corner is the border's most distal (least y) vertex;
- the ulnar head's dome: the most distal ulna vertex up to `HEAD_WIDTH_MM` ulnar of the head's radial
  border (its seat in the sigmoid notch: the greatest z of the ulna's distal `HEAD_DEPTH_MM`), which
  leaves the styloid (further ulnar) out.

Both are read on bone: a built-in participant's radius is myo-sim's mesh there (`radius_bone` leaves the
rebuilt fossae out: they are a contact surface made from the row, `anatomy.radius_cap`, and their ulnar
edge follows the lunate's curvature, not the radius').

`BuildParams.ulnar_variance_mm` moves the ulna along y until the rule gives the value asked
(`seat_ulna`), before anything of the build is made from it (`builder.pipeline.build_model`).
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

RIM_Y_MM = 6.0
"""The radius' distal end: vertices less than this proximal of the RCS origin (mm, along y) hold its
ulnar corner."""
BORDER_MM = 1.0
"""The radius' ulnar border: its distal end's vertices within this of the most ulnar one (mm, along z)."""
HEAD_WIDTH_MM = 8.0
"""The ulnar head's dome: ulna vertices up to this far ulnar of the head's radial border (mm, along z); the
styloid lies further ulnar."""
HEAD_DEPTH_MM = 10.0
"""The ulna's distal end, whose most radial vertex is the head's radial border: its vertices less than
this proximal of its most distal one (mm, along y)."""
AXIS = np.array([0.0, 1.0, 0.0])
"""The radius' long axis in the RCS (+ proximal), along which the variance is measured and the ulna moved."""


class Variance(NamedTuple):
    """The corner rule's reading (mm, RCS): the variance (+ ulna plus), the radius' ulnar corner's y and
    the ulnar head's most distal y."""

    variance_mm: float
    corner_y: float
    head_y: float


def ulnar_corner(radius_v: np.ndarray) -> np.ndarray:
    """The radius' ulnar corner (3,), RCS mm, on its vertices (n, 3) (see the module)."""
    radius_v = np.asarray(radius_v, float)
    rim = radius_v[radius_v[:, 1] < RIM_Y_MM]
    if not len(rim):
        raise ValueError(f"no radius vertex less than {RIM_Y_MM:g} mm proximal of the RCS origin (y)")
    border = rim[rim[:, 2] <= rim[:, 2].min() + BORDER_MM]
    return border[np.argmin(border[:, 1])]


def ulnar_dome(ulna_v: np.ndarray) -> np.ndarray:
    """The ulnar head's dome (3,), RCS mm, on the ulna's vertices (n, 3) (see the module)."""
    ulna_v = np.asarray(ulna_v, float)
    if not len(ulna_v):
        raise ValueError("no ulna vertex")
    distal = ulna_v[ulna_v[:, 1] <= ulna_v[:, 1].min() + HEAD_DEPTH_MM]
    head = ulna_v[ulna_v[:, 2] >= distal[:, 2].max() - HEAD_WIDTH_MM]
    return head[np.argmin(head[:, 1])]


def ulnar_variance(radius_v: np.ndarray, ulna_v: np.ndarray) -> Variance:
    """The corner rule (see the module) on the radius' bone and the ulna's vertices (n, 3), RCS mm (a
    radius `BoneSurface`'s bone: `radius_bone`)."""
    corner, dome = ulnar_corner(radius_v), ulnar_dome(ulna_v)
    return Variance(float(corner[1] - dome[1]), float(corner[1]), float(dome[1]))


def radius_bone(radius) -> np.ndarray:
    """The vertices (n, 3) of a radius `BoneSurface` on which the corner rule reads its corner: those
    outside its articular solid where it has both (a built-in participant's radius: the rebuilt fossae,
    solid, on myo-sim's distal radius, whose ulnar border they do not reach), else all of them (a
    participant folder's radius, its own bone)."""
    v, solid = np.asarray(radius.vertices), np.asarray(radius.solid, bool)
    return v[~solid] if solid.any() and not solid.all() else v


def moved_ulna(bones: dict, shift_mm: float) -> dict:
    """`bones` with the ulna translated `shift_mm` along `AXIS` (+ proximal); its vertex masks, cartilage
    and TFCC layer, per vertex, move with it."""
    v = np.asarray(bones["ulna"].vertices, float) + shift_mm * AXIS
    v.setflags(write=False)
    return {**bones, "ulna": dataclasses.replace(bones["ulna"], vertices=v)}


def built_variance(report: dict) -> float | None:
    """The ulnar variance (mm) a built model's ulna sits at (`Model.report`): as seated, plus any osteotomy;
    None where the corner rule found no corner or head."""
    r = report.get("ulnar_variance_mm")
    return None if not r else r["seated"] + r.get("osteotomy_mm", 0.0)


def seat_ulna(bones: dict, variance_mm: float) -> tuple[dict, dict]:
    """`bones` (name -> `BoneSurface`, RCS mm) with the ulna moved along `AXIS` so that `ulnar_variance`
    gives `variance_mm` (a translation: the head's vertices stay the head's), and what was done: the
    variance as given and as seated, and the shift (mm, + proximal)."""
    ulna, radius = bones["ulna"], radius_bone(bones["radius"])
    given = ulnar_variance(radius, ulna.vertices).variance_mm
    shift = given - float(variance_mm)
    moved = moved_ulna(bones, shift)
    seated = ulnar_variance(radius, moved["ulna"].vertices).variance_mm
    return moved, {"given": round(given, 4), "seated": round(seated, 4), "shift_mm": round(shift, 4)}
