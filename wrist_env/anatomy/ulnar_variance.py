"""Ulnar variance (issue 54): the corner rule that measures it, and the ulna's seat that sets it.

Ulnar variance is the level of the ulnar head's articular dome against that of the radius' ulnar
corner (the sigmoid notch's distal rim), along the radius' long axis: + where the ulna reaches further
distal (ulna plus; the adult mean +0.26 mm, Yoshioka 2007; adults measure about −4…+5 mm). Here the axis
is the RCS's y (the radius' long axis, + proximal), and the two levels are read off the meshes
(`ulnar_variance`, issue 54's step-0 rule):

- the radius' ulnar corner: its most ulnar (least z) vertex among those less than `RIM_Y_MM` proximal of
  the RCS origin (the distal end; the shaft's ulnar border lies further proximal);
- the ulnar head: the most distal (least y) ulna vertex up to `HEAD_WIDTH_MM` ulnar of that corner,
  which leaves the styloid (further ulnar) out.

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
HEAD_WIDTH_MM = 8.0
"""The ulnar head beside the sigmoid notch: ulna vertices up to this far ulnar of the radius' ulnar corner
(mm, along z); the styloid lies further ulnar."""
AXIS = np.array([0.0, 1.0, 0.0])
"""The radius' long axis in the RCS (+ proximal), along which the variance is measured and the ulna moved."""


class Variance(NamedTuple):
    """The corner rule's reading (mm, RCS): the variance (+ ulna plus), the radius' ulnar corner's y and
    the ulnar head's most distal y."""

    variance_mm: float
    corner_y: float
    head_y: float


def ulnar_variance(radius_v: np.ndarray, ulna_v: np.ndarray) -> Variance:
    """The corner rule (see the module) on the radius' and the ulna's vertices (n, 3), RCS mm."""
    radius_v, ulna_v = np.asarray(radius_v, float), np.asarray(ulna_v, float)
    rim = radius_v[radius_v[:, 1] < RIM_Y_MM]
    if not len(rim):
        raise ValueError(f"no radius vertex less than {RIM_Y_MM:g} mm proximal of the RCS origin (y)")
    corner = rim[np.argmin(rim[:, 2])]
    head = ulna_v[(ulna_v[:, 2] <= corner[2]) & (ulna_v[:, 2] >= corner[2] - HEAD_WIDTH_MM)]
    if not len(head):
        raise ValueError(f"no ulna vertex within {HEAD_WIDTH_MM:g} mm ulnar of the radius' ulnar corner")
    return Variance(float(corner[1] - head[:, 1].min()), float(corner[1]), float(head[:, 1].min()))


def seat_ulna(bones: dict, variance_mm: float) -> tuple[dict, dict]:
    """`bones` (name -> `BoneSurface`, RCS mm) with the ulna moved along `AXIS` so that `ulnar_variance`
    gives `variance_mm` (a translation: the head's vertices stay the head's), and what was done: the
    variance as given and as seated, and the shift (mm, + proximal)."""
    ulna = bones["ulna"]
    given = ulnar_variance(bones["radius"].vertices, ulna.vertices).variance_mm
    shift = given - float(variance_mm)
    v = np.asarray(ulna.vertices, float) + shift * AXIS
    v.setflags(write=False)
    moved = {**bones, "ulna": dataclasses.replace(ulna, vertices=v)}
    seated = ulnar_variance(bones["radius"].vertices, v).variance_mm
    return moved, {"given": round(given, 4), "seated": round(seated, 4), "shift_mm": round(shift, 4)}
