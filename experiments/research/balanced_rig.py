"""Research probe (issue 33): the tendon tensions that hold the wrist at neutral, and where the load goes then.

Under a rig's published tensions the prescribed capitate rotation absorbs the moment the tendon lines
leave on the distal row (`free_hand.py`). A rig without a hand fixture holds the posture by its
tensions instead. For each participant (population design, 100 N in all): the least relative change
of each line's tension (Σ (Δtᵢ / tᵢ)², tensions ≥ 0, the total kept) that zeroes the held moment about
the flexion (z) and deviation (x) axes, by Newton steps on the held moment's Jacobian over the
tensions (finite differences, each a loaded run to equilibrium); then the tensions per tendon, the
moment left, and the load shares (`validation.load_shares_pct`) and RS/RL at the balanced rig.

Run: `python experiments/research/balanced_rig.py P1 [P2 ...] [--rig erhart2020]`.
"""

from __future__ import annotations

import argparse
from dataclasses import replace

import numpy as np
from free_hand import distal_row_moment, summary
from scipy.optimize import minimize

from wrist_env import design
from wrist_env.anatomy.tendons import RIGS
from wrist_env.participants.registry import load_model
from wrist_env.solver import drivers
from wrist_env.solver import simulate as sim
from wrist_env.validation import NEUTRAL_LOAD_N

AXES = [0, 2]  # the held moment's components zeroed: deviation (x) and flexion (z)
STEP_N = 2.0  # the finite-difference change of one line's tension
NEWTON_STEPS = 3


def run_with(model, d, base, tensions):
    """A loaded run at neutral under the base driver's lines at `tensions` (N each); (driver, result)."""
    lines = replace(base.loads, share=tensions / tensions.sum(), name="custom")
    driver = replace(base, load_n=np.array([tensions.sum()]), loads=lines)
    return driver, sim.simulate(model, d, driver)


def held(model, d, base, tensions) -> np.ndarray:
    return distal_row_moment(model, d, *run_with(model, d, base, tensions))


def balance(model, d, base, t0):
    """Newton steps toward zero held moment about `AXES` at the least relative change of the tensions."""
    t = t0.copy()
    for _ in range(NEWTON_STEPS):
        M = held(model, d, base, t)
        J = np.zeros((3, len(t)))
        for i in range(len(t)):
            dt = np.zeros(len(t))
            dt[i] = STEP_N
            J[:, i] = (held(model, d, base, t + dt) - M) / STEP_N
        cons = [
            {"type": "eq", "fun": lambda x, J=J, M=M: (M + J @ (x - t))[AXES]},
            {"type": "eq", "fun": lambda x: x.sum() - t0.sum()},
        ]
        fit = minimize(
            lambda x: np.sum(((x - t0) / t0) ** 2), t, constraints=cons, bounds=[(0.0, None)] * len(t), method="SLSQP"
        )
        t = fit.x
    return t, held(model, d, base, t)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("participants", nargs="+")
    parser.add_argument("--rig", default="erhart2020", choices=sorted(RIGS))
    args = parser.parse_args()
    d = design.population()
    tendons = list(RIGS[args.rig])
    for name in args.participants:
        model = load_model(name)
        base = drivers.loaded(model, [np.eye(3)], NEUTRAL_LOAD_N, direction=args.rig)
        t0 = NEUTRAL_LOAD_N * base.loads.share
        t, M = balance(model, d, base, t0)
        _, result = run_with(model, d, base, t)
        change = ", ".join(f"{k} {a:.1f}→{b:.1f}" for k, a, b in zip(tendons, t0, t) if abs(b - a) > 0.05)
        print(
            f"{name}, balanced {args.rig}: {change} N; moment left {np.round(M, 1)} N·mm; {summary(model, result)}",
            flush=True,
        )


if __name__ == "__main__":
    main()
