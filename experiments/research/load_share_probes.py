"""Probes of the radiocarpal load share (issue 10): what moves RS/RL at neutral, and where the row gives way.

For each participant (population design, capitate held at neutral, translations free):

- the load ladder, 1-300 N: RS/RL, the capitate's translation (mm) and the scaphoid's and lunate's
  rotation (deg) from their neutral poses — where the proximal row collapses under axial load;
- conforming STT and triquetrohamate (TH) joints: the distal row's contact samples of the joint
  (trapezium and trapezoid; hamate) moved onto the opposing cartilage (neutral gap 0 where it was
  up to 3 mm), as if those surfaces conformed like the capitolunate; RS/RL and the joints'
  contact forces at 100 N (Viegas 1993: STT 23 %, TH 20 % of the midcarpal load);
- the RSC three times stiffer (30 N/mm against Table 2's 10): the scaphoid's volar sling.

Each probe changes only the built model's arrays or the design (nothing in the solver). Run:
`python experiments/research/load_share_probes.py P1 P2`.
"""

from __future__ import annotations

import dataclasses
import sys

import numpy as np
from load_paths import signed_distance  # this folder's script (on sys.path when run)
from scipy.spatial.transform import Rotation

from wrist_env import design, ligaments
from wrist_env.model import BODY_PARTS, BONES, PAIR_BONES, PAIRS
from wrist_env.participants.registry import load_model
from wrist_env.solver import drivers
from wrist_env.solver import simulate as sim
from wrist_env.solver.outputs import pair_slice, pressure_map, sample_parts

LADDER_N = (1.0, 10.0, 100.0, 200.0, 250.0, 300.0)
PROBE_N = 100.0
CLOSED_GAP_MM = 3.0  # neutral gaps up to this are closed by a conforming joint
RS, RL, SC, LC = (PAIRS.index(p) for p in ("radioscaphoid", "radiolunate", "scaphocapitate", "lunocapitate"))
STT = (SC, ("trapezium", "trapezoid"))  # the distal row's samples of the STT joint: (pair, parts)
TH = (LC, ("hamate",))  # of the triquetrohamate joint


def _neutral(model, d, load_n):
    return sim.simulate(model, d, drivers.loaded(model, [np.eye(3)], load_n=load_n))


def _ratio(result) -> float:
    return float(result.contact[0, RS, 3] / result.contact[0, RL, 3])


def _joint_samples(model, joint):
    """Mask over the pair's samples on the joint's distal-row parts, and the pair's slice."""
    pair, names = joint
    owner, s = sample_parts(model, PAIRS[pair]), pair_slice(model, PAIRS[pair])
    parts = BODY_PARTS[BONES[PAIR_BONES[pair][0]]]
    return np.isin(owner, [parts.index(n) for n in names]), s


def conforming(model, joint):
    """The model with the joint's distal-row contact samples moved onto the opposing cartilage surface."""
    mask, s = _joint_samples(model, joint)
    points = model.sample_points[s].copy()
    gap, grad = signed_distance(model, PAIR_BONES[joint[0]][1], points)
    move = mask & np.isfinite(gap) & (gap > 0) & (gap <= CLOSED_GAP_MM)
    points[move] -= gap[move, None] * grad[move] / np.linalg.norm(grad[move], axis=1, keepdims=True)
    all_points = model.sample_points.copy()
    all_points[s] = points
    return dataclasses.replace(model, sample_points=all_points)


def joint_force(model, result, joint) -> float:
    """Contact force (N, Σ pressure × area) on the joint's distal-row samples."""
    mask, s = _joint_samples(model, joint)
    return float((pressure_map(model, result.poses[0])[s] * model.sample_area[s])[mask].sum())


def main(names) -> None:
    pop = design.population()
    for name in names:
        model = load_model(name)
        print(f"\n{name}: load ladder at neutral (population design)")
        print("| load (N) | RS/RL | capitate translation (mm) | scaphoid / lunate rotation (deg) |\n|---|---|---|---|")
        for load in LADDER_N:
            r = _neutral(model, pop, load)
            if not r.ok:
                print(f"| {load:g} | {r.message} | | |")
                continue
            cap = np.linalg.norm(r.poses[0, BONES.index("capitate"), :3, 3])
            rot = [
                np.linalg.norm(Rotation.from_matrix(r.poses[0, BONES.index(b), :3, :3]).as_rotvec(degrees=True))
                for b in ("scaphoid", "lunate")
            ]
            print(f"| {load:g} | {_ratio(r):.2f} | {cap:.2f} | {rot[0]:.1f} / {rot[1]:.1f} |")
        rsc = ligaments.LIGAMENT_NAMES.index("RSC")
        stiff = pop.stiffness.copy()
        stiff[rsc] *= 3.0
        print(f"\n{name}: probes at neutral, {PROBE_N:g} N")
        print("| probe | RS/RL | STT force (N) | TH force (N) |\n|---|---|---|---|")
        for label, m, d in (
            ("as built", model, pop),
            (f"conforming STT (gaps ≤ {CLOSED_GAP_MM:g} mm closed)", conforming(model, STT), pop),
            (f"conforming TH (gaps ≤ {CLOSED_GAP_MM:g} mm closed)", conforming(model, TH), pop),
            ("conforming STT and TH", conforming(conforming(model, STT), TH), pop),
            ("RSC × 3 (30 N/mm)", model, dataclasses.replace(pop, stiffness=stiff)),
        ):
            r = _neutral(m, d, PROBE_N)
            print(f"| {label} | {_ratio(r):.2f} | {joint_force(m, r, STT):.1f} | {joint_force(m, r, TH):.1f} |")


if __name__ == "__main__":
    main(sys.argv[1:] or ["P1"])
