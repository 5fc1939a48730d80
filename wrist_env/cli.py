"""`wrist-bench`: the command line of wrist-env (a thin shell over the package)."""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from wrist_env.design import Design
    from wrist_env.model import Model
    from wrist_env.solver.simulate import Driver

FIGURES_HELP = "$WRIST_ENV_FIGURES or experiments/figures"  # wrist_env.figures.draw.FIGURES (no matplotlib import here)


def _participants(args) -> int:
    from wrist_env.participants import builtin, registry

    for name in registry.participants():
        if name in builtin.BUILTIN:
            i = builtin.info(name)
            print(f"{name}  built-in (synthetic)  {i.sex}, {i.age} y, facet type {i.facet_type}, task: {i.task}")
        else:
            print(f"{name}  folder {registry.folder(name)}")
    return 0


def _build(args) -> int:
    from wrist_env.participants import registry

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


def load_design(spec: str, participant: str) -> Design:
    """`population`, `truth` (a built-in participant's hidden ground truth) or a JSON file of a Design."""
    from wrist_env import design
    from wrist_env.errors import DesignError
    from wrist_env.participants import builtin

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


def make_driver(model: Model, motion: str, frames: int | None, flexion: float, extension: float) -> Driver:
    """The capitate driver of `simulate`: an idealized sweep or the capitate held at neutral."""
    from wrist_env.solver import simulate

    if motion == "idealized":
        return simulate.idealized(model, flexion_deg=flexion, extension_deg=extension, n_frames=frames or 17)
    return simulate.static(model, frames or 3)


def _simulate(args) -> int:
    from wrist_env.model import BONES, PAIRS
    from wrist_env.participants import registry
    from wrist_env.solver import simulate
    from wrist_env.solver.outputs import cardan_deg, result_to_dict

    if args.frames is not None and args.frames < 1:
        raise SystemExit("wrist-bench simulate: --frames must be at least 1")
    start = time.perf_counter()
    model = registry.load_model(args.participant)
    load_seconds = time.perf_counter() - start
    d = load_design(args.design, args.participant)
    driver = make_driver(model, args.motion, args.frames, args.flexion, args.extension)
    compile_seconds = None
    if args.warm_up:
        start = time.perf_counter()
        simulate.simulate(model, d, make_driver(model, args.motion, 1, 0.0, 0.0))
        compile_seconds = time.perf_counter() - start
    start = time.perf_counter()
    result = simulate.simulate(model, d, driver)
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


def _evaluate(args) -> int:
    from wrist_env.envs.task import task
    from wrist_env.frames import DOF_NAMES, DOF_UNITS
    from wrist_env.participants import registry

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


def _validate(args) -> int:
    from wrist_env import validation
    from wrist_env.builder.pipeline import BuildParams, anatomy_params
    from wrist_env.participants import registry
    from wrist_env.solver.simulate import IDEALIZED_LOAD_N

    registry.require(args.participant)
    params = anatomy_params(args)
    report = validation.validate(
        args.participant, params=params, load_n=IDEALIZED_LOAD_N if args.load is None else args.load
    )
    variant = "" if params == BuildParams() and args.load is None else "_variant"
    from wrist_env.figures.draw import FIGURES as figures_dir

    out = Path(args.out or figures_dir) / f"validation_{report.participant}{variant}.png"
    figure = validation.validation_figure(report, out)
    if args.json:
        print(json.dumps(dict(report.to_dict(), figure=str(figure)), indent=1, allow_nan=False))
    else:
        print(validation.format_table(report))
        print(f"figure: {figure}")
    return 0 if report.passed else 1


def _figure(args) -> int:
    from wrist_env import figures

    out = Path(args.out) if args.out else None
    if args.kind == "model":
        path = figures.model_figure(args.participant or "P1", out)
    elif args.kind == "annotations":
        path = figures.annotations_figure(out)
    elif args.kind == "pressure":
        path = figures.pressure_figure(args.participant or "P1", out, static=args.static)
    elif args.kind == "kinematics":
        path = figures.kinematics_figure(args.participant or "P1", out)
    else:
        raise SystemExit(f"unknown figure {args.kind!r}")
    print(path)
    return 0


def _calibrate(args) -> int:
    from wrist_env.bench.calibrate import calibrate
    from wrist_env.bench.leaderboard import reference
    from wrist_env.design import LIGAMENT_NAMES
    from wrist_env.participants import registry

    registry.require(args.participant)
    if args.budget < 1:
        raise SystemExit("wrist-bench calibrate: --budget must be at least 1")
    start = time.perf_counter()
    run = calibrate(args.participant, args.optimizer, args.budget, args.seed, log=args.log, storage=args.storage)
    wall = time.perf_counter() - start
    ref = reference(args.participant)
    out = run.to_dict(history=True)
    out["wall_seconds"] = round(wall, 3)
    out["population"] = {m: ref.population[m]["cost"] for m in ("calibrate", "validate")}
    out["truth"] = None if ref.truth is None else {m: ref.truth[m]["cost"] for m in ("calibrate", "validate")}
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(out, indent=1, allow_nan=False))
    if args.json:
        print(json.dumps(out, indent=1, allow_nan=False))
        return 0
    truth = out["truth"]
    print(
        f"{args.participant}: {args.optimizer}, seed {args.seed}: {run.result.nfev} evaluations"
        f"{f' ({run.replayed} replayed from the log)' if run.replayed else ''} in {wall:.1f} s; {run.result.message}"
    )
    for motion, name in (("calibrate", "calibration trial"), ("validate", "held-out resisted trial")):
        score = getattr(run, motion)
        print(
            f"{name + ' cost:':<30} population {out['population'][motion]:.3f} -> calibrated {score['cost']:.3f}"
            + ("" if truth is None else f"  (hidden truth {truth[motion]:.3f})")
            + (" FAILED" if score["failed"] else "")
        )
    if run.recovery_z is not None:
        print(
            f"{'parameter recovery:':<30} {run.recovery_z:.3f} SD from the truth (population design "
            f"{run.recovery_z_population:.3f})"
        )
    d = run.design
    print("calibrated design (injury scalars intact):")
    print(f"  {'ligament':<8} {'stiffness N/mm':>15} {'reference strain':>17}")
    for i, lig in enumerate(LIGAMENT_NAMES):
        print(f"  {lig:<8} {d.stiffness[i]:15.2f} {d.reference_strain[i]:17.4f}")
    if args.out:
        print(f"written to {args.out} (usable as --design of simulate and evaluate)")
    return 0


def _benchmark(args) -> int:
    import optimizers
    from wrist_env.bench.leaderboard import write_leaderboard
    from wrist_env.bench.runner import benchmark, make_cells
    from wrist_env.participants import builtin

    participants = args.participants or list(builtin.BUILTIN)
    names = args.optimizers or list(optimizers.available())
    if args.seeds < 1 or args.budget < 1:
        raise SystemExit("wrist-bench benchmark: --seeds and --budget must be at least 1")
    cells = make_cells(participants, names, args.seeds, args.budget)
    where = f"the dask scheduler {args.scheduler}" if args.scheduler else "local processes"
    print(
        f"{len(cells)} cells: participants {', '.join(participants)} x calibrators {', '.join(names)} x "
        f"{args.seeds} seeds, budget {args.budget}; on {where}; run log {args.out}",
        flush=True,
    )
    report = benchmark(
        participants,
        names,
        args.seeds,
        args.budget,
        args.out,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=not args.no_progress,
        storage=args.storage,
        threads=args.threads,
        folders=tuple(args.folder or ()),
    )
    print(
        f"ran {len(report.ran)} cells, skipped {len(report.skipped)} already finished, "
        f"{len(report.failed)} failed; {report.evaluations} evaluations logged"
    )
    for key, error in report.failed:
        print(f"  failed {key.name}: {error}", file=sys.stderr)
    if args.scheduler is None:
        print(f"local: {report.workers} worker process(es) x {report.threads} Numba thread(s)")
    print(f"wall time {report.wall_seconds:.1f} s")
    leaderboard = Path(args.leaderboard) if args.leaderboard else Path(args.out) / "leaderboards"
    if report.ran or report.skipped:
        path = write_leaderboard(args.out, leaderboard)
        print(f"leaderboard: {path}")
    return 1 if report.failed else 0


def _leaderboard(args) -> int:
    from wrist_env.bench.leaderboard import write_leaderboard

    if not Path(args.runs).is_dir():
        raise SystemExit(f"wrist-bench leaderboard: no run log at {args.runs}")
    path = write_leaderboard(args.runs, args.out, title=args.title)
    print(path)
    return 0


def _montecarlo(args) -> int:
    from wrist_env.montecarlo.study import StudyConfig, run_study
    from wrist_env.participants import registry

    registry.require(*args.participants)
    config = StudyConfig(tuple(args.participants), args.n, args.seed, args.tear_probability)
    where = (
        f"the dask scheduler {args.scheduler}"
        if args.scheduler
        else f"{args.workers} local worker processes"
        if args.workers > 1
        else "this process (Numba threads on every core)"
    )
    print(
        f"Monte Carlo: {', '.join(config.participants)}, {config.n:,} successful runs each, seed {config.seed}, "
        f"batch {args.batch}, on {where}; run log {args.out}",
        flush=True,
    )
    summary = run_study(
        config,
        args.out,
        batch=args.batch,
        scheduler=args.scheduler,
        workers=args.workers,
        folders=tuple(args.folder or ()),
        progress=not args.no_progress,
    )
    print(summary.line())
    return 0


def _montecarlo_report(args) -> int:
    from wrist_env.montecarlo.report import write_report

    if not Path(args.runs).is_dir():
        raise SystemExit(f"wrist-bench montecarlo-report: no Monte Carlo run log at {args.runs}")
    summary = write_report(args.runs, args.out, max_runs=args.max_runs)
    t5 = summary["table5"]
    print(
        f"Table 5: {t5['runs']:,} runs, {t5['rows']:,} rows, fit {t5['fit_seconds']} s; "
        f"report {summary['report_seconds']} s; written to {args.out}"
    )
    return 0


def parser() -> argparse.ArgumentParser:
    from wrist_env.builder.pipeline import add_anatomy_arguments
    from wrist_env.design import INJURABLE, SPAN_SD
    from wrist_env.montecarlo.sampler import EXCLUDE_ABOVE_MPA, TEAR_PROBABILITY

    p = argparse.ArgumentParser(prog="wrist-bench", description=__doc__)
    sub = p.add_subparsers(dest="command", required=True)
    folders = argparse.ArgumentParser(add_help=False)
    folders.add_argument(
        "--folder",
        action="append",
        help="register this participant folder first (repeatable; registered in every worker too)",
    )

    def command(name, **kwargs):
        return sub.add_parser(name, parents=[folders], **kwargs)

    s = command("participants", help="list the known participants")
    s.set_defaults(run=_participants)

    s = command("build", help="build (or load from cache) a participant model")
    s.add_argument("participant")
    s.add_argument("--json", action="store_true", help="print the build summary as JSON")
    s.add_argument("--no-cache", action="store_true", help="rebuild even if a cached model exists")
    s.set_defaults(run=_build)

    s = command(
        "simulate",
        help="simulate a participant and print the per-frame outputs",
        description="Simulate one participant and design; print per-frame kinematics, contact, ligament "
        "forces and the wall time of the simulate call. The first call in a fresh environment "
        "includes Numba compilation (later calls read Numba's on-disk cache; each new process "
        "still pays ~0.2 s to load it): --warm-up runs a one-frame simulation first and reports "
        "its time as compile_seconds, so that wall_seconds is the solver alone.",
    )
    s.add_argument("participant")
    s.add_argument(
        "--motion",
        choices=["idealized", "static"],
        default="idealized",
        help="idealized: capitate swept from --flexion to --extension about the RCS z axis under a "
        "small compressive load (default); static: capitate held at neutral (experimental "
        "driver with identity transforms)",
    )
    s.add_argument(
        "--design",
        default="population",
        help="'population' (Table 2 means, default), 'truth' (a built-in participant's hidden "
        "ground truth) or a JSON file of a design (Design.as_dict)",
    )
    s.add_argument("--frames", type=int, help="number of output frames (default 17 idealized, 3 static)")
    s.add_argument("--flexion", type=float, default=40.0, help="idealized: first frame's flexion, deg (default 40)")
    s.add_argument("--extension", type=float, default=40.0, help="idealized: last frame's extension, deg (default 40)")
    s.add_argument("--warm-up", action="store_true", help="run a one-frame simulation first (compile_seconds)")
    s.add_argument("--json", action="store_true", help="print all per-frame outputs as JSON")
    s.set_defaults(run=_simulate)

    s = command(
        "evaluate",
        help="score one design on a participant's task (cost, per-DOF errors)",
        description="Simulate one design on a participant's task and print its kinematic cost with the 75th "
        "percentile |error| and the RMSE of each scaphoid and lunate DOF (mm, deg) against the "
        "reference: the calibration trial (default), the held-out validation trial, or the idealized "
        "sweep (reference: the hidden truth's sweep for built-in participants; none, cost 0, for "
        "user participants). Exit status 1 if the simulation failed.",
    )
    s.add_argument("participant")
    s.add_argument(
        "--motion",
        choices=["calibrate", "validate", "idealized"],
        default="calibrate",
        help="calibrate: the trial with role calibrate (default); validate: the trial with role "
        "validate; idealized: the flexion-extension sweep",
    )
    s.add_argument(
        "--design",
        default="population",
        help="'population' (Table 2 means, default), 'truth' (a built-in participant's hidden "
        "ground truth) or a JSON file of a design (Design.as_dict)",
    )
    s.add_argument("--json", action="store_true", help="print the cost, per-DOF errors and timings as JSON")
    s.set_defaults(run=_evaluate)

    s = command(
        "validate",
        help="check the model against published wrist measurements (exit 1 if any check fails)",
        description="Simulate the population design (idealized +-40 deg sweep intact and with all three SLIL bundles "
        "torn, and the capitate held at neutral) and compare carpal kinematics, radiocarpal load share, "
        "SL gap after SLIL tear, radioscaphoid pressure and SLIL force with published bands (each row "
        "cites its source). Prints the table (or JSON) and writes a figure; exit status 1 if any check "
        "fails.",
    )
    s.add_argument("participant")
    s.add_argument("--json", action="store_true", help="print the checks and series as JSON")
    s.add_argument("--out", help=f"figure folder (default {FIGURES_HELP})")
    add_anatomy_arguments(s)
    s.add_argument(
        "--load",
        type=float,
        help="compressive load on the capitate in the sweeps, N (default: the idealized "
        "driver's; the load-share check always takes 100 N)",
    )
    s.set_defaults(run=_validate)

    s = command(
        "figure",
        help="write a figure (PNG)",
        description="model: bones, cartilage, ligaments; annotations: the template; pressure: "
        "contact pressure at the neutral pose viewed from distal (population design); "
        "kinematics: scaphoid and lunate rotations over an idealized sweep.",
    )
    s.add_argument("kind", choices=["model", "annotations", "pressure", "kinematics"])
    s.add_argument("participant", nargs="?")
    s.add_argument("--out", help="output PNG path")
    s.add_argument(
        "--static",
        action="store_true",
        help="pressure: capitate held at neutral without load, instead of the 0° frame of the "
        "idealized sweep (10 N compressive load)",
    )
    s.set_defaults(run=_figure)

    s = command(
        "calibrate",
        help="calibrate a participant's ligament materials with one calibrator",
        description="Search the 22 ligament material variables (injury scalars intact) to minimize the kinematic "
        "cost on the participant's calibration trial, with a registered calibrator "
        "(`optimizers.available()`); then score the calibrated design on the held-out resisted trial "
        "and, for built-in participants, against the hidden truth (parameter recovery, Table 2 SD "
        "units). Prints the calibrated design in physical units.",
    )
    s.add_argument("participant")
    s.add_argument("--optimizer", default="cmaes", help="calibrator name (default cmaes)")
    s.add_argument("--budget", type=int, default=300, help="simulations allowed (default 300)")
    s.add_argument("--seed", type=int, default=0, help="calibrator seed (default 0)")
    s.add_argument("--log", help="run-log folder: log every batch, resume this run if it was cut short")
    s.add_argument("--storage", help="Optuna storage URL for Optuna calibrators (default: in memory)")
    s.add_argument("--out", help="also write the JSON result to this file (usable as --design elsewhere)")
    s.add_argument("--json", action="store_true", help="print the result, design and held-out cost as JSON")
    s.set_defaults(run=_calibrate)

    s = command(
        "benchmark",
        help="run participants x calibrators x seeds into a resumable run log, then the leaderboard",
        description="Cross participants x calibrators x seeds, one cell each, on local processes (default) or a "
        "dask.distributed scheduler; every evaluation is logged to Parquet in --out as its batch "
        "finishes. Run the same command again to resume after an interruption: finished cells are "
        "skipped, unfinished ones replay their logged evaluations. Writes the leaderboard at the end.",
    )
    s.add_argument("--participants", nargs="+", help="default: the built-in P1 P2 P3")
    s.add_argument("--optimizers", nargs="+", help="default: every registered calibrator")
    s.add_argument("--seeds", type=int, default=5, help="seeds 0 .. N-1 per participant and calibrator (default 5)")
    s.add_argument("--budget", type=int, default=300, help="simulations per run (default 300)")
    s.add_argument("--out", default="runs/benchmark", help="run-log folder (default runs/benchmark)")
    s.add_argument("--scheduler", help="dask.distributed scheduler address (e.g. tcp://host:8786); one task per cell")
    s.add_argument("--workers", type=int, help="local worker processes (default: one per core)")
    s.add_argument("--threads", type=int, help="Numba threads per local worker (default: cores / workers)")
    s.add_argument(
        "--storage",
        help="Optuna storage URL, '{cell}' replaced by the cell's key (default: "
        "sqlite:///<out>/optuna/{cell}.db); 'memory': studies in memory only",
    )
    s.add_argument("--leaderboard", help="leaderboard folder (default: <out>/leaderboards)")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.set_defaults(run=_benchmark)

    s = command(
        "leaderboard",
        help="write the leaderboards of a benchmark run log",
        description="Tables (Markdown, CSV) and figures (PNG) from a benchmark run log: best cost "
        "at the budget, evaluations to cost targets, ECDF and convergence plots, "
        "parameter recovery, the held-out trial, the preprint's Tables 3-4.",
    )
    s.add_argument("--runs", default="runs/benchmark", help="run-log folder (default runs/benchmark)")
    s.add_argument("--out", default="leaderboards", help="output folder (default leaderboards)")
    s.add_argument("--title", help="title of the README.md")
    s.set_defaults(run=_leaderboard)

    s = command(
        "montecarlo",
        help="Monte Carlo injury study: n successful idealized sweeps per participant (preprint 2.3.2)",
        description=f"Latin hypercube over the 27 design variables (materials from Table 2's normals truncated at "
        f"+-{SPAN_SD:g} SD, each of {', '.join(INJURABLE)} torn with probability {TEAR_PROBABILITY:g}), "
        f"simulated through the Idealized environment; runs whose radioscaphoid mean pressure exceeds "
        f"{EXCLUDE_ABOVE_MPA:g} MPa at any frame are excluded and, like solver failures, replaced until n "
        f"runs succeed. Every run is logged to Parquet in --out as its batch finishes; run the same "
        f"command again to resume.",
    )
    s.add_argument("participants", nargs="+")
    s.add_argument("--n", type=int, default=12500, help="successful runs per participant (default 12500)")
    s.add_argument("--seed", type=int, default=0, help="study seed (default 0)")
    s.add_argument(
        "--tear-probability",
        type=float,
        default=TEAR_PROBABILITY,
        help=f"chance of each tear (default {TEAR_PROBABILITY:g})",
    )
    s.add_argument("--out", default="runs/montecarlo", help="run-log folder (default runs/montecarlo)")
    s.add_argument("--scheduler", help="dask.distributed scheduler address (e.g. tcp://host:8786); one task per batch")
    s.add_argument(
        "--batch", type=int, default=64, help="runs per batch: one vector-env step, one log part (default 64)"
    )
    s.add_argument(
        "--workers",
        type=int,
        default=0,
        help="local worker processes, which die with this one (default 0, or 1: this process, "
        "Numba threads on every core)",
    )
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.set_defaults(run=_montecarlo)

    s = sub.add_parser(
        "montecarlo-report",
        help="Tables 5-6 and Figures 8-10 of a Monte Carlo run log",
        description="Mixed-effects fits (statsmodels MixedLM) of radioscaphoid pressure on a 2-df "
        "angle spline and the tears (Table 5) and of SLIL bundle forces in intact runs "
        "(Table 6), with a random intercept per run; tables as Markdown and CSV, figures "
        "as PNG, summary.json and report.md.",
    )
    s.add_argument("--runs", default="runs/montecarlo", help="run-log folder (default runs/montecarlo)")
    s.add_argument("--out", default="leaderboards/montecarlo", help="output folder (default leaderboards/montecarlo)")
    s.add_argument("--max-runs", type=int, help="fit on a seeded random subset of this many runs (default: all)")
    s.set_defaults(run=_montecarlo_report)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    args = parser().parse_args(argv)
    from wrist_env.errors import WristEnvError

    try:
        if getattr(args, "folder", None):
            from wrist_env.participants import registry

            for folder in args.folder:
                registry.add_folder(folder)
        return args.run(args)
    except WristEnvError as exc:  # every project error (unknown calibrators too): one line, exit 2
        print(f"wrist-bench: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
