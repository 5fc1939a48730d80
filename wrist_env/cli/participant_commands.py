"""`wrist-bench` commands on one participant: participants, build, export, simulate, evaluate (their
arguments; `wrist_env.cli.run.participants` runs them)."""

from __future__ import annotations

import argparse
from collections.abc import Callable

from wrist_env.cli.options import (
    json_option,
    participant_argument,
)
from wrist_env.limits import MAX_FRAMES, MAX_SWEEP_DEG, bounded_float, bounded_int
from wrist_env.motions import DRIVEN_MOTIONS, MOTIONS
from wrist_env.solver.settings import SOLVERS

FIGURES_HELP = "$WRIST_ENV_FIGURES or runs/figures"  # where wrist_env.figures.draw.FIGURES points
DESIGN_HELP = (
    "'population' (Table 2 means, default), 'truth' (a built-in participant's hidden ground truth) "
    "or a JSON file of a design (Design.as_dict; calibrate --out writes one)"
)


def add_solver_argument(parser) -> None:
    """--solver: the named solver settings (`settings.SOLVERS`)."""

    parser.add_argument(
        "--solver",
        choices=SOLVERS,
        default="default",
        help="the solver: default (the block mass, the membrane subcycled, the sweep's frames predicted; "
        "docs/solver.md, 'The preconditioned solver') or diagonal (each bone's scaled mass, the default before)",
    )


def add_commands(command: Callable[..., argparse.ArgumentParser]) -> None:
    """Add these commands; `command(name, **kwargs)` makes a subcommand's parser."""

    s = command(
        "participants",
        description="List the participants this command can use: the built-in P1-P3 (synthetic, with their "
        "Table 1 facts) and the participant folders registered with --folder.",
    )
    s.set_defaults(run="participants:participants")

    s = command(
        "build",
        description="Build a participant's model (morph the template, cartilage, ligament fibres, contact law, "
        "signed-distance grids; ~30-45 s on first use) and cache it by the hash of its inputs; later "
        "calls load the cache. Prints the build summary.",
    )
    participant_argument(s)
    json_option(s, "the build summary")
    s.add_argument("--no-cache", action="store_true", help="rebuild even if a cached model exists")
    s.set_defaults(run="participants:build")

    s = command(
        "export",
        description="Write a built-in participant (its five bone meshes as STL, RCS mm; its trials as CSV; "
        "participant.toml) as a participant folder that build, evaluate, calibrate and "
        "wrist_env.register_participant accept unchanged: the starting point for a folder of your own. "
        "The folder's participant is named after the folder (or --name).",
    )
    participant_argument(s, "built-in participant to export: P1, P2 or P3")
    s.add_argument("out_folder", metavar="folder", help="new folder to write (must not exist or be empty)")
    s.add_argument("--name", help="the exported participant's name (default: the folder's name)")
    s.set_defaults(run="participants:export")

    s = command(
        "simulate",
        description="Simulate one participant and design; print per-frame kinematics, contact, ligament "
        "forces and the wall time of the simulate call. The first call in a fresh environment "
        "includes Numba compilation (later calls read Numba's on-disk cache; each new process "
        "still pays ~0.2 s to load it): --warm-up runs a one-frame simulation first and reports "
        "its time as compile_seconds, so that wall_seconds is the solver alone.",
    )
    participant_argument(s)
    s.add_argument(
        "--motion",
        choices=DRIVEN_MOTIONS,
        default="idealized",
        help="idealized: capitate swept from --flexion to --extension about the RCS z axis under a "
        "small compressive load (default); static: capitate held at neutral (experimental "
        "driver with identity transforms); calibrate, validate: the capitate through the participant's "
        "trial of that role, under its recorded load (its frames: no --frames)",
    )
    s.add_argument("--design", default="population", help=DESIGN_HELP)
    s.add_argument(
        "--frames",
        type=bounded_int("frames", 1, MAX_FRAMES),
        help="number of output frames (default 17 idealized, 3 static)",
    )
    angle = bounded_float("the sweep's angle", -MAX_SWEEP_DEG, MAX_SWEEP_DEG, "deg")
    s.add_argument("--flexion", type=angle, default=40.0, help="idealized: first frame's flexion, deg (default 40)")
    s.add_argument("--extension", type=angle, default=40.0, help="idealized: last frame's extension, deg (default 40)")
    s.add_argument("--warm-up", action="store_true", help="run a one-frame simulation first (compile_seconds)")
    json_option(s, "all per-frame outputs")
    add_solver_argument(s)
    s.set_defaults(run="participants:simulate")

    s = command(
        "evaluate",
        description="Simulate one design on a participant's task and print its kinematic cost with the 75th "
        "percentile |error| and the RMSE of each scaphoid and lunate DOF (mm, deg) against the "
        "reference: the calibration trial (default), the held-out validation trial, or the idealized "
        "sweep (reference: the hidden truth's sweep for built-in participants; none, cost 0, for "
        "user participants). Exit status 1 if the simulation failed.",
    )
    participant_argument(s)
    s.add_argument(
        "--motion",
        choices=MOTIONS,
        default="calibrate",
        help="calibrate: the trial with role calibrate (default); validate: the trial with role "
        "validate; idealized: the flexion-extension sweep",
    )
    s.add_argument("--design", default="population", help=DESIGN_HELP)
    json_option(s, "the cost, per-DOF errors and timings")
    s.set_defaults(run="participants:evaluate")
