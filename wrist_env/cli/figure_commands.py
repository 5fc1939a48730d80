"""`wrist-bench` commands that check and draw a participant's model: validate, figure."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from pathlib import Path

from wrist_env import figures, validation
from wrist_env.builder.params import BuildParams, add_anatomy_arguments, anatomy_params
from wrist_env.cli.options import PARTICIPANT_HELP, json_option, load_direction_option, out_option, participant_argument
from wrist_env.cli.participant_commands import FIGURES_HELP, add_solver_argument
from wrist_env.errors import UsageError
from wrist_env.figures.draw import FIGURES as figures_dir
from wrist_env.figures.validation import validation_figure
from wrist_env.io import write_json
from wrist_env.participants import registry
from wrist_env.solver.arrays import solver_settings
from wrist_env.solver.drivers import DEFAULT_LOADS, IDEALIZED_LOAD_N


def _validate(args) -> int:

    registry.require(args.participant)
    params = anatomy_params(args)
    report = validation.validate(
        args.participant,
        params=params,
        load_n=IDEALIZED_LOAD_N if args.load is None else args.load,
        load_direction=args.load_direction,
        settings=solver_settings(args.solver),
    )
    default = (
        params == BuildParams()
        and args.load is None
        and args.load_direction == DEFAULT_LOADS
        and args.solver == "default"
    )
    variant = "" if default else "_variant"

    out = Path(args.out or figures_dir) / f"validation_{report.participant}{variant}.png"
    figure = validation_figure(report, out)
    write_json(out.with_suffix(".json"), report.to_dict())  # the record the docs' validation page renders
    if args.json:
        print(json.dumps(dict(report.to_dict(), figure=str(figure)), indent=1, allow_nan=False))
    else:
        print(validation.format_table(report))
        print(f"figure: {figure} (and its record, {out.with_suffix('.json').name})")
    return 0 if report.passed else 1


def _figure(args) -> int:

    out = Path(args.out) if args.out else None
    if args.kind == "model":
        path = figures.model_figure(args.participant or "P1", out)
    elif args.kind == "annotations":
        path = figures.annotations_figure(out)
    elif args.kind == "pressure":
        path = figures.pressure_figure(args.participant or "P1", out, static=args.static)
    elif args.kind == "kinematics":
        path = figures.kinematics_figure(args.participant or "P1", out)
    elif args.kind == "animation":
        path = figures.animation_figure(args.participant or "P1", out)
    else:
        raise UsageError(f"unknown figure {args.kind!r}")
    print(path)
    return 0


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
        type=float,
        help="compressive load on the capitate in the sweeps, N (default: the idealized "
        "driver's; the load-share check always takes 100 N)",
    )
    load_direction_option(
        s,
        "the loads' direction: along the radius (default), or the resultant at neutral of a tendon "
        "rig's tensions along myo-sim's tendon paths (Erhart 2020; see anatomy/tendons.py)",
    )
    add_solver_argument(s)
    s.set_defaults(run=_validate)

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
    s.set_defaults(run=_figure)
