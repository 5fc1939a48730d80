"""Research probe (issue 33): what the driver holds at neutral, and whether the hand could be let free to turn.

The loaded driver prescribes the capitate's rotation, so it absorbs the moment the tendon lines and the
joints leave on the distal row. For each participant (population design, 100 N on a tendon rig's lines):
the moment the driver absorbs at neutral (N·mm, RCS, about the capitate's centre of mass), the load
shares there (`validation.load_shares_pct`), and the distal row's rotational stiffness
K = −∂M/∂θ (N·mm/rad, central differences of ±`STEP_RAD` about each RCS axis, each a loaded run to
equilibrium): a hand free in rotation has an equilibrium near neutral only if K is positive definite
and K⁻¹M is small.

Run: `python experiments/research/free_hand.py P1 [P2 ...] [--load-direction erhart2020]`.
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.spatial.transform import Rotation

from wrist_env import design
from wrist_env.participants.registry import load_model
from wrist_env.solver import drivers
from wrist_env.solver import simulate as sim
from wrist_env.solver.outputs import articulation_forces, driven_body_load
from wrist_env.solver.settings import LOAD_DIRECTIONS
from wrist_env.validation import NEUTRAL_LOAD_N, load_shares_pct

STEP_RAD = 0.02  # the finite-difference turn (1.1 deg)


def distal_row_moment(model, d, driver, result) -> np.ndarray:
    """The net moment (N·mm, RCS, about the capitate's centre of mass) of contacts, ligaments and the
    driver's lines on the distal row at the run's first frame: what the driver holds
    (`outputs.driven_body_load`)."""
    return driven_body_load(model, d, driver, result.poses[0], result.membrane_nodes[0])[1]


def run(model, d, rotvec, direction):
    driver = drivers.loaded(model, [Rotation.from_rotvec(rotvec).as_matrix()], NEUTRAL_LOAD_N, direction=direction)
    result = sim.simulate(model, d, driver)
    return driver, result


def summary(model, result) -> str:
    f = articulation_forces(model, result.poses[0])
    s = load_shares_pct(model, result)
    return (
        f"RS/RL {f['radioscaphoid'] / f['radiolunate']:.2f}, STT/SC/LC/TH "
        f"{s['scaphotrapeziotrapezoid']:.1f}/{s['scaphocapitate']:.1f}/{s['lunocapitate']:.1f}/"
        f"{s['triquetrohamate']:.1f} %, ulnar {s['ulnocarpal']:.1f} %"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("participants", nargs="+")
    parser.add_argument("--load-direction", default="erhart2020", choices=LOAD_DIRECTIONS)
    args = parser.parse_args()
    d = design.population()
    for name in args.participants:
        model = load_model(name)
        driver, neutral = run(model, d, np.zeros(3), args.load_direction)
        held = distal_row_moment(model, d, driver, neutral)
        print(
            f"{name}, neutral: the driver holds {np.round(held, 1)} N·mm ({np.linalg.norm(held):.0f}); {summary(model, neutral)}"
        )

        K = np.zeros((3, 3))
        for k in range(3):
            q = np.zeros(3)
            q[k] = STEP_RAD
            plus = distal_row_moment(model, d, *run(model, d, q, args.load_direction))
            minus = distal_row_moment(model, d, *run(model, d, -q, args.load_direction))
            K[:, k] = -(plus - minus) / (2 * STEP_RAD)
        sym = 0.5 * (K + K.T)
        turn = np.degrees(np.linalg.solve(K, held))
        print(
            f"{name}: rotational stiffness K (N·mm/rad, rows M, columns θ about x, y, z) {np.round(K).tolist()}; "
            f"eigenvalues of its symmetric part {np.round(np.linalg.eigvalsh(sym)).tolist()}; "
            f"the turn K⁻¹M that would balance the held moment, linearly: {np.round(turn, 1)} deg",
            flush=True,
        )


if __name__ == "__main__":
    main()
