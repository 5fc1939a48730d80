"""What sets the explicit solver's step count: the free bones' natural frequencies at equilibrium.

For the population design on each participant's idealized sweep and calibration trial, linearizes
the force kernels at three settled frames (`equilibrium.tangent_stiffness`: central differences,
the RSC membrane's free nodes condensed out) and prints the free bones' natural frequencies
ω (rad/s, from K u = ω² M u with the solver's scaled masses), the spread ω_max / ω_min, and the
time step each limits: dt·ω_max for the bones and dt·ω for the membrane's free nodes at the node
mass the design runs with (`arrays.node_mass`). An explicit step is stable below dt·ω = 2
(`arrays.COURANT` = 1.5 for the nodes); a slow mode needs ~1 / (dt·ω_min) steps per e-fold of its
error, so the hold's step count follows ω_max / ω_min once the step sits at the stiffest mode's limit.
Also printed per frame: the bones' span and spread under the block mass
(`SolverSettings()`, the membrane condensed) and the membrane's free nodes' own span
at their mass with the bones held (what the block mass leaves slowest).

Run: `python experiments/verification/stiffness_spectrum.py [P1 P2 P3]` (~10 s per participant).
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.linalg import eigh

from wrist_env import design
from wrist_env.participants import registry
from wrist_env.participants.registry import load_model
from wrist_env.solver import arrays
from wrist_env.solver.drivers import idealized, trial_driver
from wrist_env.solver.equilibrium import block_mass, tangent_stiffness
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import prepare, simulate, stiffness


def node_courant(model, dsg, driver, settings: SolverSettings) -> float:
    """dt·ω of the membrane's stiffest free-node mode at the design's node mass (`arrays.node_mass`)."""
    p = prepare(model, settings, driver.mode)
    st = stiffness(p, dsg)
    stiffest = arrays.membrane_stiffest(p.settings, p.membrane_eigenvalue, st.m_l0, st.m_K)
    return settings.dt_s * float(np.sqrt(stiffest / st.node_mass))


def report(name: str, settings: SolverSettings) -> None:
    model = load_model(name)
    dsg = design.population()
    motions = {
        "sweep": idealized(model),
        "trial": trial_driver(model, registry.trial(name, "calibrate")),
    }
    for motion, driver in motions.items():
        result = simulate(model, dsg, driver, settings)
        frames = [1, driver.n_frames // 2, driver.n_frames - 1]
        print(f"{name} {motion}: membrane nodes dt·ω {node_courant(model, dsg, driver, settings):.2f}")
        node_mass = stiffness(prepare(model, settings, driver.mode), dsg).node_mass
        for f in frames:
            tangent = tangent_stiffness(model, dsg, driver, result, f, settings)
            omega = tangent.frequencies()
            blocks = block_mass(model, dsg, driver, result, f, SolverSettings())
            w2 = eigh(tangent.stiffness, blocks.mass, eigvals_only=True)
            block = np.sqrt(w2[w2 > 0.0])
            nodes = np.linalg.eigvalsh(tangent.membrane)
            nodes = np.sqrt(np.clip(nodes, 0.0, None) / node_mass)
            soft = nodes[nodes > 1e-6 * nodes[-1]]
            print(
                f"  frame {f:2d}: ω {np.nanmin(omega):6.0f} … {np.nanmax(omega):6.0f} rad/s "
                f"(spread {np.nanmax(omega) / np.nanmin(omega):4.1f}); bones dt·ω_max {settings.dt_s * np.nanmax(omega):.2f}, "
                f"dt·ω_min {settings.dt_s * np.nanmin(omega):.3f}; {result.steps[f]} steps\n"
                f"            under the block mass: dt·ω {settings.dt_s * block.min():.3f} … {settings.dt_s * block.max():.2f} "
                f"(spread {block.max() / block.min():4.1f}); the membrane's nodes alone (bones held): dt·ω "
                f"{settings.dt_s * soft.min():.4f} … {settings.dt_s * nodes.max():.2f}, "
                f"{int(np.sum(nodes <= 1e-6 * nodes[-1]))} modes without stiffness"
            )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("participants", nargs="*", default=["P1", "P2", "P3"])
    args = parser.parse_args(argv)
    settings = SolverSettings().diagonal()
    print(f"time step {settings.dt_s:g} s; explicit stability limit dt·ω = 2")
    for name in args.participants:
        report(name, settings)


if __name__ == "__main__":
    main()
