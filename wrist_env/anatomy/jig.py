"""The hand loaded axially, as in the cadaver jigs the midcarpal and radiocarpal load shares were measured in.

Tencer et al. 1988 and Viegas et al. 1993 (the bands of `validation.bands`' midcarpal shares and RS/RL)
loaded the hand axially through the metacarpals in a jig, not through the tendons: a check is only fair
under its experiment's load mode (issue 54). Without metacarpals in the model, the jig's load enters each
distal carpal where its metacarpals meet it: along the radius' long axis (`drivers.AXIAL`), through the
area-weighted centroid of the carpal's carpometacarpal (CMC) facets, shared among the carpals by their CMC
facet areas — an equal mean pressure over the CMC joints, for no per-ray share of a jig's load is
published. The facets are measured on myo-sim's metacarpals as myo-sim assembles them (the template's
RCS, seated with the distal row): a carpal faces a metacarpal whose surface comes within `CMC_REACH_MM`
of it, and its facet is its surface within `CMC_BAND_MM` beyond that closest approach (myo-sim's bones are
not assembled for contact, so the band stands for the joint's cartilage gap).
"""

from __future__ import annotations

import functools
import importlib.resources
import xml.etree.ElementTree as ET

import numpy as np
import trimesh

from wrist_env.anatomy import tendons
from wrist_env.anatomy.midcarpal import read_seat
from wrist_env.anatomy.myosim import CHAIN_XML, radius_frame_transforms
from wrist_env.anatomy.template import load_template, vertex_areas

DISTAL_CARPALS = ("trapezium", "trapezoid", "capitate", "hamate")
"""The carpals the metacarpals meet (`model.PARTS`)."""
METACARPALS = {"firstmc_r": "1mc.stl", "secondmc_r": "2mc.stl", "thirdmc_r": "3mc.stl", "fourthmc_r": "4mc.stl"}
METACARPALS |= {"fifthmc_r": "5mc.stl"}
"""myo-sim's metacarpal bodies and their meshes."""
CMC_REACH_MM = 3.0
"""A carpal faces a metacarpal whose surface comes within this of it (mm)."""
CMC_BAND_MM = 1.0
"""A CMC facet: the carpal's vertices within this beyond its closest approach to the metacarpal (mm)."""


def metacarpal_meshes() -> dict:
    """myo-sim's five metacarpals (body name -> trimesh, mm) in the template's RCS, seated with the distal row
    (`anatomy.midcarpal`)."""
    pkg = importlib.resources.files("myo_sim")
    in_radius = radius_frame_transforms(ET.parse(str(pkg / CHAIN_XML)).getroot())
    template, seat = load_template(), read_seat()
    out = {}
    for body, stl in METACARPALS.items():
        mesh = trimesh.load(str(pkg / "models" / "meshes" / stl), force="mesh", process=True)
        v = (in_radius[body] @ np.c_[mesh.vertices, np.ones(len(mesh.vertices))].T).T[:, :3]
        v = np.array([tendons._to_rcs(body, p, template.rcs_from_myosim, seat) for p in v])
        out[body] = trimesh.Trimesh(v, mesh.faces, process=False)
    return out


@functools.cache
def cmc_facets() -> dict:
    """Per distal carpal: {"area": its CMC facets' area (mm²), "centroid": their area-weighted centroid (3,)
    (RCS mm, the template), "metacarpals": the metacarpal bodies it faces} (see the module)."""
    parts = load_template().parts
    mcs = metacarpal_meshes()
    out = {}
    for carpal in DISTAL_CARPALS:
        mesh = parts[carpal].trimesh()
        vertex_area = vertex_areas(mesh.vertices, mesh.faces)
        facing = np.zeros(len(mesh.vertices), bool)
        names = []
        for body, mc in mcs.items():
            d = np.abs(trimesh.proximity.signed_distance(mc, mesh.vertices))
            if d.min() <= CMC_REACH_MM:
                facing |= d <= d.min() + CMC_BAND_MM
                names.append(body)
        area = vertex_area[facing]
        out[carpal] = {
            "area": float(area.sum()),
            "centroid": (mesh.vertices[facing] * area[:, None]).sum(axis=0) / area.sum(),
            "metacarpals": tuple(names),
        }
    return out


def model_lines(model) -> tuple:
    """The jig's load on a participant model, as `tendons.model_lines` gives a rig's: (body (n,) index into
    `BONES`, point (n, 3) mm in the model's neutral pose, direction (n, 3) the radius' axis, share (n,) by
    CMC area), one line per distal carpal, its facets' centroid carried with it (`tendons.carry_point`)."""
    facets = cmc_facets()
    body, point = zip(*(tendons.carry_point(model, c, facets[c]["centroid"]) for c in DISTAL_CARPALS))
    area = np.array([facets[c]["area"] for c in DISTAL_CARPALS])
    arrays = (
        np.array(body, np.int64),
        np.array(point),
        np.tile([0.0, 1.0, 0.0], (len(area), 1)),
        area / area.sum(),
    )
    for a in arrays:
        a.setflags(write=False)
    return arrays
