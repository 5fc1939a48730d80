"""How `wrist-bench` runs the commands on one participant: participants, build, export, simulate, evaluate
(declared in `wrist_env.cli.participant_commands`)."""

from __future__ import annotations

import argparse
import dataclasses
import json
import re
import time
from pathlib import Path
from typing import TYPE_CHECKING

from wrist_env import design
from wrist_env.cli.run.outputs import out_folder
from wrist_env.errors import DesignError, ParticipantError
from wrist_env.frames import DOF_NAMES, DOF_UNITS
from wrist_env.model import BONES, PAIRS
from wrist_env.motions import STATIC, TRIAL_MOTIONS
from wrist_env.participants import builtin, registry
from wrist_env.participants.folder import NAME_PATTERN, PARTICIPANT_FILE, write_participant_folder
from wrist_env.solver import drivers
from wrist_env.solver import simulate as simulation
from wrist_env.solver.outputs import cardan_deg, result_to_dict
from wrist_env.solver.settings import solver_settings
from wrist_env.task import task

if TYPE_CHECKING:
    from wrist_env.design import Design


def participants(args) -> int:

    for name in registry.participants():
        if name in builtin.BUILTIN:
            i = builtin.info(name)
            print(f"{name}  built-in (synthetic)  {i.sex}, {i.age} y, facet type {i.facet_type}, task: {i.task}")
        else:
            print(f"{name}  folder {registry.folder(name)}")
    return 0


def build(args) -> int:

    start = time.perf_counter()
    model = registry.load_model(args.participant, cache=not args.no_cache)
    summary = dict(model.report)
    summary["wall_seconds"] = round(time.perf_counter() - start, 2)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(
            f"{model.name}: built in {summary['build_seconds']} s "
            f"(this call {summary['wall_seconds']} s); morph error (mm): "
            + ", ".join(f"{b} {e['mean']:.2f}/{e['max']:.2f}" for b, e in summary["morph_error_mm"].items())
        )
    return 0


def export(args: argparse.Namespace) -> int:

    if args.participant not in builtin.BUILTIN:
        raise ParticipantError(
            f"export takes a built-in participant {list(builtin.BUILTIN)}, but got {args.participant!r} "
            "(a folder participant is a folder already)"
        )
    if args.name is not None and not args.name.strip():
        raise ParticipantError(
            "--name is empty; give the exported participant's name, or leave --name out to use the folder's"
        )
    out = out_folder(args.out_folder, "export's folder")
    name = args.name if args.name is not None else out.resolve().name
    if name in builtin.BUILTIN or not re.fullmatch(NAME_PATTERN, name):
        raise ParticipantError(
            f"the exported participant needs a name matching {NAME_PATTERN} that is not a built-in one, "
            f"but got {name!r} (give --name)"
        )
    if out.exists() and any(out.iterdir()):
        raise ParticipantError(f"{out} exists and is not empty; export writes a new folder")
    source = dataclasses.replace(builtin.source(args.participant), name=name)
    folder = write_participant_folder(source, out)
    print(
        f"wrote {args.participant} as participant {name!r} to {folder} ({PARTICIPANT_FILE}, bones/*.stl, "
        f"trials/*.csv); use it with --folder {folder}"
    )
    return 0


def load_design(spec: str, participant: str) -> Design:
    """`population`, `truth` (a built-in participant's hidden ground truth) or a JSON file of a Design."""

    if spec == "population":
        return design.population()
    if spec == "truth":
        if participant not in builtin.BUILTIN:
            raise DesignError(
                f"--design truth needs a built-in participant {list(builtin.BUILTIN)}, but got {participant!r}"
            )
        return builtin.truth(participant)
    if not Path(spec).is_file():
        raise DesignError(
            f"--design must be 'population', 'truth' or a JSON file of a design, but {spec!r} is none of these"
        )
    return design.read_json(spec)


def simulate(args) -> int:

    start = time.perf_counter()
    model = registry.load_model(args.participant)
    load_seconds = time.perf_counter() - start
    d = load_design(args.design, args.participant)
    trial = registry.trial(args.participant, args.motion) if args.motion in TRIAL_MOTIONS else None
    sweep = {"flexion_deg": args.flexion, "extension_deg": args.extension}
    driver = drivers.for_motion(model, args.motion, trial, n_frames=args.frames, **sweep)
    compile_seconds = None

    settings = solver_settings(args.solver)
    if args.warm_up:
        start = time.perf_counter()
        # one frame of the same kind of driver (the kernel is the same; a trial's driver is the experimental one)
        warm = STATIC if args.motion in TRIAL_MOTIONS else args.motion
        simulation.simulate(
            model, d, drivers.for_motion(model, warm, n_frames=1, flexion_deg=0.0, extension_deg=0.0), settings
        )
        compile_seconds = time.perf_counter() - start
    start = time.perf_counter()
    result = simulation.simulate(model, d, driver, settings)
    wall = time.perf_counter() - start
    if args.json:
        out = {
            "participant": model.name,
            "motion": args.motion,
            "design": args.design,
            "wall_seconds": round(wall, 4),
            "compile_seconds": None if compile_seconds is None else round(compile_seconds, 4),
            "load_seconds": round(load_seconds, 4),
        }
        out.update(result_to_dict(result, model))
        print(json.dumps(out, indent=1, allow_nan=False))
        return 0 if result.ok else 1
    flex = cardan_deg(result.poses)[..., 0].round(2) + 0.0  # + 0.0: no "-0.00"
    c, s, l = (BONES.index(b) for b in ("capitate", "scaphoid", "lunate"))
    rs = PAIRS.index("radioscaphoid")
    print(f"{model.name}, {args.motion} motion, design {args.design}: flexion (+) about the RCS z axis, deg")
    print(f"{'frame':>5}  {'capitate':>8}  {'scaphoid':>8}  {'lunate':>8}  {'RS mean MPa':>11}  {'RS peak MPa':>11}")
    for f in range(len(result.poses)):
        print(
            f"{f:>5}  {flex[f, c]:8.2f}  {flex[f, s]:8.2f}  {flex[f, l]:8.2f}  "
            f"{result.contact[f, rs, 0]:11.3f}  {result.contact[f, rs, 1]:11.3f}"
        )
    timing = f"simulate {wall:.3f} s" + ("" if compile_seconds is None else f" (warm-up {compile_seconds:.3f} s)")
    print(f"status: {result.message}; {timing}; model load {load_seconds:.2f} s")
    return 0 if result.ok else 1


def evaluate(args) -> int:

    registry.require(args.participant)
    d = load_design(args.design, args.participant)
    start = time.perf_counter()
    t = task(args.participant, args.motion)
    load_seconds = time.perf_counter() - start
    start = time.perf_counter()
    evaluation = t.evaluate(d)
    wall = time.perf_counter() - start
    info = evaluation.info
    out = {
        "participant": args.participant,
        "motion": args.motion,
        "design": args.design,
        "failed": bool(evaluation.failed),
        "status": info["status"],
        "cost": evaluation.cost,
        "error_p75": info.get("error_p75"),
        "rmse": info.get("rmse"),
        "cost_terms": info.get("cost_terms"),
        "units": dict(zip(DOF_NAMES, DOF_UNITS)),
        "n_frames": len(evaluation.result.poses),
        "wall_seconds": round(wall, 4),
        "load_seconds": round(load_seconds, 4),
    }
    if args.json:
        print(json.dumps(out, indent=1, allow_nan=False))
        return 1 if evaluation.failed else 0
    print(f"{args.participant}, {args.motion} motion ({out['n_frames']} frames), design {args.design}")
    if out["error_p75"] is None:
        print("no reference kinematics (a user participant's idealized sweep): cost 0 by definition")
    else:
        print(f"{'bone':<9} {'DOF':<10} {'p75 error':>9} {'RMSE':>8}  unit")
        for bone, errors in out["error_p75"].items():
            for dof, unit in zip(DOF_NAMES, DOF_UNITS):
                p75, rmse = errors[dof], out["rmse"][bone][dof]
                p75, rmse = ("nan" if x is None else f"{x:.3f}" for x in (p75, rmse))
                print(f"{bone:<9} {dof:<10} {p75:>9} {rmse:>8}  {unit}")
    print(
        f"cost {evaluation.cost:.4f}{' (failed)' if evaluation.failed else ''}; status: {info['status']}; "
        f"evaluate {wall:.3f} s; task setup {load_seconds:.2f} s"
    )
    return 1 if evaluation.failed else 0
