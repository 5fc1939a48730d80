"""`wrist-bench` commands that check and draw a participant's model: validate, figure (their arguments;
`wrist_env.cli.run.figures` runs them)."""

from __future__ import annotations

import argparse
from collections.abc import Callable

from wrist_env.builder.params import add_anatomy_arguments
from wrist_env.cli.options import PARTICIPANT_HELP, json_option, load_direction_option, out_option, participant_argument
from wrist_env.cli.participant_commands import FIGURES_HELP, add_solver_argument
from wrist_env.limits import MAX_LOAD_N, bounded_float


def add_commands(command: Callable[..., argparse.ArgumentParser]) -> None:
    """Add validate and figure."""
    s = command(
        "validate",
        description="Simulate the population design (idealized +-40 deg sweep intact and with all three SLIL bundles "
        "torn, and the capitate held at neutral) and compare carpal kinematics, radiocarpal load share, "
        "SL gap after SLIL tear, radioscaphoid pressure and SLIL force with published bands (each row "
        "cites its source). Prints the table (or JSON) and writes a figure and its JSON record; exit status 1 if any check "
        "fails.",
    )
    participant_argument(s)
    json_option(s, "the checks and series")
    out_option(s, what=f"figure folder (default {FIGURES_HELP})")
    add_anatomy_arguments(s)
    s.add_argument(
        "--load",
        type=bounded_float("load", 0.0, MAX_LOAD_N, "N, compressive"),
        help="compressive load on the capitate in the sweeps, N (default: the idealized "
        "driver's; the load-share checks always take 100 N)",
    )
    load_direction_option(
        s,
        "the sweeps' loads (see simulate); the neutral load-share checks (RS/RL, midcarpal, ulnar) take "
        "the hand loaded axially as in their experiments' jigs (jig; see anatomy/jig.py)",
    )
    add_solver_argument(s)
    s.set_defaults(run="figures:validate")

    s = command(
        "figure",
        description="model: bones, cartilage, ligaments; annotations: the template; pressure: "
        "contact pressure at the neutral pose viewed from distal (population design); "
        "kinematics: scaphoid and lunate rotations over an idealized sweep; animation: a GIF of that sweep "
        "(radial view: bones, ligament fibres coloured by force, radiocarpal contact pressure).",
    )
    s.add_argument("kind", choices=["model", "annotations", "pressure", "kinematics", "animation"])
    participant_argument(s, PARTICIPANT_HELP + " (default P1)", nargs="?")
    out_option(s, what=f"output PNG path (default: a file named after the figure in {FIGURES_HELP})")
    s.add_argument(
        "--static",
        action="store_true",
        help="pressure: capitate held at neutral without load, instead of the 0° frame of the "
        "idealized sweep (10 N compressive load)",
    )
    s.set_defaults(run="figures:figure")
