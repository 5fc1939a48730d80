"""Where each injury moves the load in the Monte Carlo study's sweep (issue 33: Table 5's signs).

For each participant, the population design intact and with each injury scalar of the Monte Carlo
study torn (`montecarlo.sampler.TORN_ACTION`, one at a time), simulated on the study's driver (the
idealized ±40° sweep under its load on the default lines), this prints the sweep's means of the
radioscaphoid mean pressure (MPa, the study's response) and contact area (mm²), the contact forces (N) of the radioscaphoid,
radiolunate, STT, scaphocapitate, lunocapitate and ulnocarpal pairs, and the scaphoid's and lunate's
flexion slopes, each as the change from intact. Table 5 compares the study's estimates with the
preprint's; this says through which joints an injury's estimate arises.

Run: `python experiments/research/injury_load_paths.py [P1 P2]`
"""

from __future__ import annotations

import argparse

import numpy as np

from wrist_env import design
from wrist_env.model import BONES, PAIRS
from wrist_env.montecarlo.sampler import INTACT_ACTION, TORN_ACTION
from wrist_env.participants.registry import load_model
from wrist_env.solver.drivers import idealized
from wrist_env.solver.forces import R_AREA, R_FORCE, R_MEAN
from wrist_env.solver.outputs import cardan_deg
from wrist_env.solver.simulate import simulate_batch
from wrist_env.validation import slope

SHOWN = ("radioscaphoid", "radiolunate", "scaphotrapezial", "scaphocapitate", "lunocapitate", "ulnocarpal")


def flexion_slopes(poses: np.ndarray) -> tuple[float, float]:
    """The scaphoid's and lunate's flexion per degree of the capitate's over a sweep (`validation.slope`)."""
    flex = cardan_deg(poses)[..., 0]
    cap = flex[:, BONES.index("capitate")]
    return slope(cap, flex[:, BONES.index("scaphoid")]), slope(cap, flex[:, BONES.index("lunate")])


def designs() -> dict[str, design.Design]:
    """The population design intact and with each injurable ligament torn, by name."""
    out = {"intact": design.population()}
    for i, name in enumerate(design.INJURABLE):
        a = design.to_action(design.population())
        a[design.N_MATERIAL :] = INTACT_ACTION
        a[design.N_MATERIAL + i] = TORN_ACTION
        out[f"{name} torn"] = design.from_action(a)
    return out


def main(names) -> None:
    for name in names:
        model = load_model(name)
        cases = designs()
        results = dict(zip(cases, simulate_batch(model, list(cases.values()), idealized(model))))
        rows = {}
        for case, r in results.items():
            if not r.ok:
                rows[case] = None
                continue
            rs_pressure = float(np.nanmean(r.contact[:, PAIRS.index("radioscaphoid"), R_MEAN]))
            rs_area = float(np.mean(r.contact[:, PAIRS.index("radioscaphoid"), R_AREA]))
            forces = [float(np.mean(r.contact[:, PAIRS.index(p), R_FORCE])) for p in SHOWN]
            rows[case] = [rs_pressure, rs_area, *forces, *flexion_slopes(r.poses)]
        base = rows["intact"]
        head = [
            "RS mean pressure (MPa)",
            "RS area (mm²)",
            *(f"{p} (N)" for p in SHOWN),
            "scaphoid slope",
            "lunate slope",
        ]
        print(f"{name}, population design, the Monte Carlo sweep; intact, then each injury's change")
        print("| | " + " | ".join(head) + " |\n|---|" + "---|" * len(head))
        for case, row in rows.items():
            if row is None:
                print(f"| {case} | failed |")
                continue
            cells = row if case == "intact" else np.subtract(row, base)
            fmt = "{:.3f}" if case == "intact" else "{:+.3f}"
            print(f"| {case} | " + " | ".join(fmt.format(v) for v in cells) + " |")
        print()


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("participants", nargs="*", default=["P1", "P2"])
    main(parser.parse_args().participants)
