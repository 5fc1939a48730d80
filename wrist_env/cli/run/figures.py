"""How `wrist-bench` runs the commands that check and draw a participant's model: validate, figure
(declared in `wrist_env.cli.figure_commands`)."""

from __future__ import annotations

import json
from pathlib import Path

from wrist_env import figures, validation
from wrist_env.builder.params import BuildParams, anatomy_params
from wrist_env.cli.run import figure_data
from wrist_env.errors import UsageError
from wrist_env.figures.draw import FIGURES as figures_dir
from wrist_env.figures.validation import validation_figure
from wrist_env.io import write_json
from wrist_env.participants import registry
from wrist_env.solver.drivers import IDEALIZED_LOAD_N
from wrist_env.solver.settings import DEFAULT_LOADS, solver_settings


def validate(args) -> int:

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
    figure = validation_figure(validation.report.figure_panels(report), out)
    write_json(out.with_suffix(".json"), report.to_dict())  # the record the docs' validation page renders
    if args.json:
        print(json.dumps(dict(report.to_dict(), figure=str(figure)), indent=1, allow_nan=False))
    else:
        print(validation.format_table(report))
        print(f"figure: {figure} (and its record, {out.with_suffix('.json').name})")
    return 0 if report.passed else 1


def figure(args) -> int:

    out = Path(args.out) if args.out else None
    name = args.participant or "P1"
    if args.kind not in ("model", "annotations", "pressure", "kinematics", "animation"):
        raise UsageError(f"unknown figure {args.kind!r}")
    if args.kind == "annotations":
        path = figures.annotations_figure(*figure_data.template(), out)
        print(path)
        return 0
    model = registry.load_model(name)
    if args.kind == "model":
        path = figures.model_figure(model, name, out)
    elif args.kind == "pressure":
        path = figures.pressure_figure(model, figure_data.pressure_frame(model, name, static=args.static), out)
    elif args.kind == "kinematics":
        path = figures.kinematics_figure(name, *figure_data.row_kinematics(model, name), out)
    else:
        path = figures.animation_figure(model, figure_data.sweep_frames(model, name), out)
    print(path)
    return 0
