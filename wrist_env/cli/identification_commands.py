"""`wrist-bench` commands on what a trial can identify: sensitivity, identifiability."""

from __future__ import annotations

import time
from collections.abc import Callable


def _sensitivity(args) -> int:
    from wrist_env import sensitivity
    from wrist_env.participants import registry

    registry.require(*args.participants)
    for participant in args.participants:
        start = time.perf_counter()
        table = sensitivity.study(participant, args.method, args.n, tuple(args.motions), args.seed, args.out)
        key = "mu_star" if args.method == "morris" else "ST"
        for motion, rows in table[table["output"] == "cost"].groupby("motion", sort=False):
            top = rows.nlargest(5, key)
            ranked = ", ".join(f"{m} {v:.3g}" for m, v in zip(top["material"], top[key]))
            print(f"{participant} {motion}: cost {key} {ranked} ({rows['runs'].iloc[0]} runs)")
        print(
            f"{participant}: {args.out}/sensitivity_{participant}_{args.method}.csv and .png "
            f"in {time.perf_counter() - start:.0f} s",
            flush=True,
        )
    return 0


def _identifiability(args) -> int:
    from wrist_env import identifiability
    from wrist_env.participants import builtin

    unknown = [p for p in args.participants if p not in builtin.BUILTIN]
    if unknown:
        raise SystemExit(
            f"wrist-bench identifiability: {unknown} have no hidden truth; built-ins: {list(builtin.BUILTIN)}"
        )
    materials, spectra = identifiability.study(args.participants, args.out)
    for (participant, trials), rows in materials.groupby(["participant", "trials"], sort=False):
        s = spectra[(spectra["participant"] == participant) & (spectra["trials"] == trials)]
        pinned = rows[rows["posterior_sd"] < 0.5]["material"].tolist()
        print(
            f"{participant} {trials}: {int((s['sd'] < 1).sum())} of 22 directions pinned tighter than the prior; "
            f"materials to < 0.5 SD: {', '.join(pinned) or 'none'}"
        )
    print(f"written to {args.out}")
    return 0


def add_commands(command: Callable[..., object]) -> None:

    s = command(
        "sensitivity",
        help="global sensitivity of the cost and the 12 DOF errors to the 22 materials (SALib)",
        description="Morris screening (n trajectories, n x 23 runs per motion) or Sobol first and total "
        "indices (Saltelli, base n a power of 2, n x 24 runs per motion) of the kinematic cost and the "
        "scaphoid and lunate DOF errors to the 22 ligament materials over the action box (Table 2 mean "
        "+-3 SD), injuries intact, simulated through the vector environment; a CSV and a PNG per participant.",
    )
    s.add_argument("participants", nargs="+", help="participant names (`wrist-bench participants` lists them)")
    s.add_argument("--method", choices=("morris", "sobol"), default="morris", help="default morris")
    s.add_argument("--n", type=int, default=20, help="Morris trajectories or Sobol base size (default 20)")
    s.add_argument(
        "--motions",
        nargs="+",
        choices=("calibrate", "validate", "idealized"),
        default=["calibrate", "validate", "idealized"],
        help="default: all three",
    )
    s.add_argument("--seed", type=int, default=0, help="sampling seed (default 0)")
    s.add_argument("--out", default="runs/sensitivity", help="output folder (default runs/sensitivity)")
    s.set_defaults(run=_sensitivity)

    s = command(
        "identifiability",
        help="what the calibration and held-out trials identify at the hidden truth (Fisher matrix)",
        description="The Gauss-Newton (Fisher) matrix of the per-frame scaphoid and lunate DOF residuals over "
        "the 4DCT noise (0.2 mm, 0.5 deg), in Table 2 SD units, at each built-in participant's hidden truth "
        "(central differences, 45 runs per trial): its spectrum and each material's posterior SD with the "
        "population prior, for the calibration trial, the held-out trial and both; CSV and a PNG per participant.",
    )
    s.add_argument("participants", nargs="+", help="built-in participants (they have a hidden truth)")
    s.add_argument("--out", default="runs/identifiability", help="output folder (default runs/identifiability)")
    s.set_defaults(run=_identifiability)
