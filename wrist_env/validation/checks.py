"""`validate`: the population design's three runs and the fifteen checks against published bands."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np

from wrist_env import design as design_mod
from wrist_env.anatomy.ulnar_variance import built_variance
from wrist_env.builder.params import BuildParams
from wrist_env.limits import MAX_FRAMES, MAX_LOAD_N, check_float, check_int
from wrist_env.model import BONES, MIDCARPAL, PAIRS, Model
from wrist_env.participants.registry import load_model
from wrist_env.solver import drivers
from wrist_env.solver import simulate as sim
from wrist_env.solver.drivers import IDEALIZED_LOAD_N
from wrist_env.solver.outputs import cardan_deg
from wrist_env.solver.settings import DEFAULT_LOADS, JIG
from wrist_env.validation.bands import (
    EXTENSION_30_DEG,
    LUNOTRIQUETRAL_DEG,
    NEUTRAL_LOAD_N,
    SL_DISSOCIATION_MM,
    SLIL,
    ULNAR_SHARE_PCT,
    VIEGAS_1993,
)
from wrist_env.validation.measures import (
    at_angle,
    column_rotation_deg,
    hamate_rotation_deg,
    load_shares_pct,
    lunotriquetral_rotation_deg,
    sl_gap_mm,
    slope,
    with_tears,
)
from wrist_env.validation.report import Report, _row

if TYPE_CHECKING:
    from wrist_env.builder.params import BuildParams


def _failure(label, result) -> str | None:
    return None if result.ok else f"{label} run {result.message}"


def _mode(load: str) -> str:
    """How a neutral check was loaded, in words."""
    return "the hand loaded axially, as in a jig" if load == JIG else f"the {load} load"


def _variance_said(model: Model) -> str:
    """ ", ulnar variance +0.26 mm" as the build seated the ulna (its osteotomy included), or "" where the
    corner rule found none: the ulnar share depends on it (Werner 1986)."""
    v = built_variance(model.report)
    return "" if v is None else f", ulnar variance {v:+.2f} mm"


def validate(
    name: str,
    *,
    model: Model | None = None,
    d: design_mod.Design | None = None,
    n_frames: int = 17,
    params: BuildParams | None = None,
    load_n: float = IDEALIZED_LOAD_N,
    load_direction: str = DEFAULT_LOADS,
    neutral_load: str = JIG,
    settings=None,
) -> Report:
    """Run the published-measurement checks on participant `name` (population design by default).

    params: build parameters (`BuildParams`; the anatomy variant), default the default build.
    load_n: the compressive load (N) of the sweeps; the neutral pose takes `NEUTRAL_LOAD_N`.
    load_direction: the loads' direction in the sweeps (`settings.LOAD_DIRECTIONS`).
    neutral_load: the load at neutral, where RS/RL and the midcarpal and ulnar shares are measured: by
        default their experiments' (`settings.JIG`: the hand loaded axially in a jig, as Palmer & Werner
        1984, Tencer 1988, Hara 1992 and Viegas 1993 loaded it), not the tendons'.
    settings: the solver's (`settings.SolverSettings`), default its defaults.
    The load and the frames are checked before the model loads (a NaN load used to fail the whole run).
    """

    start = time.perf_counter()
    load_n = check_float("load_n", load_n, 0.0, MAX_LOAD_N, "N, compressive")
    n_frames = check_int("n_frames", n_frames, 1, MAX_FRAMES)
    params = params or BuildParams()
    model = model if model is not None else load_model(name, params)
    intact_design = d if d is not None else design_mod.population()
    torn_design = with_tears(intact_design, SLIL)
    direction = load_direction
    sweep = drivers.idealized(model, n_frames=n_frames, load_n=load_n, direction=direction)
    intact, torn = sim.simulate_batch(model, [intact_design, torn_design], sweep, settings)
    neutral = sim.simulate(
        model,
        intact_design,
        drivers.loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N, direction=neutral_load),
        settings,
    )

    b = {bone: BONES.index(bone) for bone in ("capitate", "scaphoid", "lunate")}
    rs, rl = PAIRS.index("radioscaphoid"), PAIRS.index("radiolunate")
    flex = cardan_deg(intact.poses)[..., 0]  # (n_frames, 5): flexion + about the RCS z axis
    cap, sca, lun = flex[:, b["capitate"]], flex[:, b["scaphoid"]], flex[:, b["lunate"]]
    s_slope, l_slope = slope(cap, sca), slope(cap, lun)
    gap_intact, gap_torn = sl_gap_mm(model, intact.poses), sl_gap_mm(model, torn.poses)
    slil = [design_mod.LIGAMENT_NAMES.index(n) for n in SLIL]
    slil_total = intact.bundle_force[:, slil].sum(axis=1)
    fail_i, fail_t, fail_n = (
        _failure("intact sweep", intact),
        _failure("SLIL-torn sweep", torn),
        _failure("neutral", neutral),
    )
    inf = float("inf")
    with np.errstate(divide="ignore", invalid="ignore"):
        rs_rl = float(neutral.contact[0, rs, 3] / neutral.contact[0, rl, 3])
    shares = load_shares_pct(model, neutral)
    rows = (
        _row(
            "scaphoid_slope",
            "scaphoid flexion per degree of capitate flexion (least squares, idealized +-40 deg sweep)",
            s_slope,
            (0.55, 0.95),
            "deg/deg",
            fail_i,
        ),
        _row(
            "lunate_slope",
            "lunate flexion per degree of capitate flexion (least squares, idealized +-40 deg sweep)",
            l_slope,
            (0.30, 0.75),
            "deg/deg",
            fail_i,
        ),
        _row(
            "scaphoid_above_lunate",
            "scaphoid slope minus lunate slope",
            s_slope - l_slope,
            (0.0, inf),
            "deg/deg",
            fail_i,
        ),
        _row(
            "rs_rl_force_ratio",
            f"radioscaphoid / radiolunate contact force, capitate held at neutral under {NEUTRAL_LOAD_N:g} N"
            f" ({_mode(neutral_load)})",
            rs_rl,
            (1.1, 2.0),
            "ratio",
            fail_n,
        ),
        *(
            _row(
                f"midcarpal_{key}_share_pct",
                f"{name}'s share of the midcarpal contact force, neutral, {NEUTRAL_LOAD_N:g} N ({_mode(neutral_load)})",
                shares[name],
                (pct - 10.0, pct + 10.0),
                "%",
                fail_n,
            )
            for (key, pct), name in zip(VIEGAS_1993.items(), MIDCARPAL)
        ),
        _row(
            "ulnar_share_pct",
            f"ulnocarpal share of the radiocarpal + ulnocarpal contact force, neutral, {NEUTRAL_LOAD_N:g} N"
            f" ({_mode(neutral_load)}){_variance_said(model)}",
            shares["ulnocarpal"],
            ULNAR_SHARE_PCT,
            "%",
            fail_n,
        ),
        _row(
            "column_rotation_deg",
            "largest rotation of the radial column (trapezium + trapezoid) relative to the capitate over the sweep",
            column_rotation_deg(intact.poses) if intact.ok else np.nan,
            (0.0, 3.0),
            "deg",
            fail_i,
        ),
        _row(
            "hamate_rotation_deg",
            "largest rotation of the hamate relative to the capitate over the sweep",
            hamate_rotation_deg(intact.poses) if intact.ok else np.nan,
            (0.0, 3.0),
            "deg",
            fail_i,
        ),
        _row(
            "lunotriquetral_rotation_deg",
            "largest rotation of the triquetrum relative to the lunate over the sweep",
            lunotriquetral_rotation_deg(intact.poses) if intact.ok else np.nan,
            (0.0, LUNOTRIQUETRAL_DEG),
            "deg",
            fail_i,
        ),
        _row(
            "sl_gap_growth_mm",
            "SL gap at full extension (last frame), all three SLIL bundles torn minus intact",
            gap_torn[-1] - gap_intact[-1],
            (SL_DISSOCIATION_MM, inf),
            "mm",
            fail_i or fail_t,
        ),
        _row(
            "rs_mean_pressure_mpa",
            "radioscaphoid mean contact pressure, mean over the sweep's frames",
            np.nanmean(intact.contact[:, rs, 0]) if intact.ok else np.nan,
            (0.2, 3.0),
            "MPa",
            fail_i,
        ),
        _row(
            "slil_force_30ext_n",
            "total SLIL force (SLIL_v + SLIL_p + SLIL_d) at 30 deg extension",
            at_angle(intact.angle_deg, slil_total, EXTENSION_30_DEG),
            (10.0, 40.0),
            "N",
            fail_i,
        ),
    )
    series = {
        "capitate_angle_deg": intact.angle_deg,
        "capitate_flexion_deg": cap,
        "scaphoid_flexion_deg": sca,
        "lunate_flexion_deg": lun,
        "sl_gap_intact_mm": gap_intact,
        "sl_gap_slil_torn_mm": gap_torn,
        "slil_force_intact_n": slil_total,
        "rs_mean_pressure_intact_mpa": intact.contact[:, rs, 0],
        "intact_status": intact.message,
        "slil_torn_status": torn.message,
        "neutral_status": neutral.message,
    }
    conditions = {
        "fossa_sweep_deg": list(params.anatomy[0]),
        "distal_row": params.anatomy[1],
        "fixed_ligaments": bool(params.fixed_ligaments and params.distal_row),
        "load_n": float(load_n),
        "load_direction": load_direction,
    }
    return Report(model.name, rows, series, time.perf_counter() - start, conditions)
