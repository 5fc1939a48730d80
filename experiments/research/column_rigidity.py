"""How stiff the distal row's joints would have to be for the column and the hamate to stay within 3°
of the capitate over the sweep (issue 54, step 5).

Akhbari et al. 2019 (J Orthop Res 37:2661) measured the distal row moving as one, each bone within 3°
of the capitate; `validate` checks it (`largest_rotation_deg`). Neither joint's
constraint that would bound that turn is measured for the radial column: no mechanical test of the
trapezoid–capitate interosseous ligament was found, and the 2nd and 3rd carpometacarpal joints, which
bind the trapezoid and capitate through the metacarpal bases, are measured only as ranges of motion
(El-Shennawy et al. 2001, J Hand Surg Am 26:1030: 11° and 7° of flexion–extension), not as a stiffness.
The hamate's is measured (Ritt et al. 1996: `ligaments.CH_JOINT_STIFFNESS`). So instead of choosing a
stiffness, this probe scales what the model has — the capitohamate joint's measured spring, and the
trapezocapitate bands (TZC_p, TZC_d: Table 2's palmar radiocarpal stiffness, borrowed) — by 1, 2, 4, 8
and 16 and prints each body's largest turn from the capitate over validate's sweep (population design,
±40°, 10 N on the erhart2020 lines): by how much each misses 3°, and how far the measured constraint
would have to be exceeded to meet it.

Run: `python experiments/research/column_rigidity.py [P1 P2 P3]` (a minute).
"""

from __future__ import annotations

import argparse
from contextlib import contextmanager
from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation

from wrist_env import design, ligaments
from wrist_env.model import CAPITATE, HAMATE, TRAPEZIUM
from wrist_env.participants.registry import load_model
from wrist_env.solver import arrays
from wrist_env.solver.drivers import idealized
from wrist_env.solver.simulate import simulate
from wrist_env.validation.checks import IDEALIZED_LOAD_N
from wrist_env.validation.measures import largest_rotation_deg

SCALES = (1.0, 2.0, 4.0, 8.0, 16.0)
COLUMN_BANDS = ("TZC_p", "TZC_d")


@contextmanager
def scaled(hamate: float = 1.0, column: float = 1.0):
    """The capitohamate joint's spring × `hamate` and the trapezocapitate bands' stiffness × `column`
    for the block (module constants read when a simulation is prepared), restored after."""
    joint, fixed = arrays.CH_JOINT_STIFFNESS, ligaments.FIXED_LIGAMENTS  # design.ligament_arrays reads its own name
    arrays.CH_JOINT_STIFFNESS = tuple(hamate * k for k in joint)
    ligaments.FIXED_LIGAMENTS = tuple(
        replace(lig, stiffness_mean=column * lig.stiffness_mean) if lig.name in COLUMN_BANDS else lig for lig in fixed
    )
    try:
        yield
    finally:
        arrays.CH_JOINT_STIFFNESS, ligaments.FIXED_LIGAMENTS = joint, fixed


def sweep(model):
    """Validate's sweep of the population design (±40°, 10 N on the erhart2020 lines)."""
    return simulate(model, design.population(), idealized(model, load_n=IDEALIZED_LOAD_N))


def turns(model) -> tuple[float, float]:
    """(the column's, the hamate's) largest turn (deg) from the capitate over validate's sweep."""
    result = sweep(model)
    if not result.ok:
        return float("nan"), float("nan")
    return largest_rotation_deg(result.poses, TRAPEZIUM), largest_rotation_deg(result.poses, HAMATE)


def turn_axis_deg(poses: np.ndarray, body: int) -> np.ndarray:
    """At the frame of `body`'s largest turn from the capitate, that turn's rotation vector (deg) in the
    capitate's frame, as (flexion: about RCS z, deviation: about x, pronation: about y)."""
    relative = np.einsum("fji,fjk->fik", poses[:, CAPITATE, :3, :3], poses[:, body, :3, :3])  # capitateᵀ · body
    vectors = np.degrees(Rotation.from_matrix(relative).as_rotvec())
    f = int(np.argmax(np.linalg.norm(vectors, axis=1)))
    return vectors[f][[2, 0, 1]]


def main(names) -> None:
    print("| participant | scale | column's turn, TZC bands × scale (deg) | hamate's turn, CH spring × scale (deg) |")
    print("|---|---|---|---|")
    for name in names:
        model = load_model(name)
        for s in SCALES:
            with scaled(column=s):
                column, _ = turns(model)
            with scaled(hamate=s):
                _, hamate = turns(model)
            print(f"| {name} | {s:g} | {column:.2f} | {hamate:.2f} |")
    print(
        "\nAkhbari 2019: within 3 deg of the capitate. At scale 1, each turn's axis at its largest, in the capitate's"
    )
    print("frame, as flexion / deviation / pronation (deg):")
    for name in names:
        poses = sweep(load_model(name)).poses
        for label, body in (("column", TRAPEZIUM), ("hamate", HAMATE)):
            f, d, p = turn_axis_deg(poses, body)
            print(f"  {name} {label}: {f:+.2f} / {d:+.2f} / {p:+.2f}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("participants", nargs="*", default=["P1", "P2", "P3"])
    main(parser.parse_args().participants)
