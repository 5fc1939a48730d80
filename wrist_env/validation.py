"""The model checked against published wrist measurements (`wrist-bench validate`).

`validate(name)` runs three simulations of the population-mean design — an
intact idealized ±40° flexion–extension sweep and the same sweep with all
three SLIL bundles torn (one batched call), and the capitate held at neutral
under the idealized compressive load — and compares twelve outputs with bands
drawn from cadaveric and in-vivo studies. Each row says where its band comes
from. A check whose simulation failed has value NaN (None in JSON), fails,
and names the solver's status in its description.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from wrist_env import design as design_mod
from wrist_env.model import BONES, CAPITATE, MIDCARPAL, PAIRS, TRAPEZIUM, Model
from wrist_env.solver.simulate import DEFAULT_LOADS, IDEALIZED_LOAD_N

if TYPE_CHECKING:
    from wrist_env.builder.pipeline import BuildParams

SLIL = ("SLIL_v", "SLIL_p", "SLIL_d")
EXTENSION_30_DEG = -30.0  # flexion + / extension −, as the idealized driver's angle_deg
SL_DISSOCIATION_MM = 3.0  # clinical scapholunate dissociation: gap > 3 mm
RAINBOW_SCAPHOID = 0.72  # Rainbow 2013: scaphoid 70 % (flexion), 74 % (extension) of the capitate
RAINBOW_LUNATE = 0.44  # Rainbow 2013: lunate 46 % (flexion), 42 % (extension)
NEUTRAL_LOAD_N = 100.0  # axial load of the load-share check: Hara 1992 loaded neutral wrists with up to 12 kg

VIEGAS_1993 = {"stt": 23, "sc": 28, "lc": 29, "th": 20}
"""Midcarpal load shares (%), Viegas 1993, in `model.MIDCARPAL` order."""
ULNAR_SHARE_PCT = (10.0, 25.0)  # Palmer & Werner 1984 (18.4 %), Hara 1992 (15 %)

RAINBOW = (
    "Rainbow et al. 2013, J Hand Surg Am 38:278-288 (in vivo CT, 12 wrists, extreme loaded flexion and "
    "extension: {} of the capitate's flexion / extension)"
)
SOURCES = {
    "scaphoid_slope": RAINBOW.format("scaphoid 70 % / 74 %"),
    "lunate_slope": RAINBOW.format("lunate 46 % / 42 %"),
    "scaphoid_above_lunate": RAINBOW.format("scaphoid 70-74 % against lunate 42-46 %"),
    "rs_rl_force_ratio": (
        "Hara et al. 1992, J Hand Surg Am 17:339-347 (neutral wrist: 50 % of the load through the "
        "scaphoid fossa, 35 % through the lunate fossa, ratio 1.43); Viegas, Tencer et al. "
        "(load transfer characteristics of the wrist): scaphoid/lunate fossa contact-area "
        "ratio 1.47"
    ),
    "sl_gap_growth_mm": (
        "Haug et al. 2021, Arch Orthop Trauma Surg 141:341-347 (8 axially loaded cadaver wrists: "
        "SL gap 6.6 +- 1.6 mm after SLIL transection); a gap > 3 mm is clinical SL dissociation"
    ),
    "rs_mean_pressure_mpa": (
        "Andreassen et al. preprint, Figure 3 / Table 5 scale (a no-regression band: Table 5's "
        "normalizer, mean RS pressure 0.65 MPa; cadaveric radiocarpal pressures of a few MPa, "
        "Hara 1992: peak 2.4 MPa on the scaphoid fossa under 10 kg)"
    ),
    **{
        f"midcarpal_{key}_share_pct": (
            f"Viegas, Patterson, Todd & McCarty 1993, J Hand Surg Am 18:14-18 (pressure-sensitive film, "
            f"cadaver wrists loaded axially in neutral: STT 23 %, SC 28 %, LC 29 %, TH 20 % of the midcarpal "
            f"load; {key.upper()} {pct} %, band +-10 points)"
        )
        for key, pct in VIEGAS_1993.items()
    },
    "ulnar_share_pct": (
        "Palmer & Werner 1984, Clin Orthop 187:26-35 (neutral ulnar variance: 18.4 % of the axial load "
        "through the ulna); Hara et al. 1992, J Hand Surg Am 17:339-347 (TFC 15 %)"
    ),
    "column_rotation_deg": (
        "Akhbari et al. 2019, J Orthop Res 37:2661-2670 (in-vivo CT, the distal row moves as one rigid "
        "body within 3 deg)"
    ),
    "slil_force_30ext_n": (
        "Dimitris et al. 2015, J Hand Surg Am 40:1525-1533 (total SLIL force in active wrist "
        "motion ~20 N, 20.0 +- 3.3 N at 30 deg extension; the preprint's ref. 63)"
    ),
}


def column_rotation_deg(poses: np.ndarray) -> float:
    """The radial column's largest rotation (deg) relative to the capitate over a run's poses (n, 6, 4, 4)."""
    relative = np.einsum("fij,fkj->fik", poses[:, TRAPEZIUM, :3, :3], poses[:, CAPITATE, :3, :3])
    cos = np.clip((np.trace(relative, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    return float(np.degrees(np.arccos(cos)).max())


@dataclass(frozen=True)
class Check:
    """One row: a model output against a published band (low <= value <= high passes; inf: unbounded)."""

    id: str
    description: str
    value: float
    band: tuple[float, float]
    unit: str
    source: str
    passed: bool

    def to_dict(self) -> dict:
        return {
            "id": self.id,
            "description": self.description,
            "value": _num(self.value),
            "band": [_num(self.band[0]), _num(self.band[1])],
            "unit": self.unit,
            "source": self.source,
            "passed": bool(self.passed),
        }


@dataclass(frozen=True)
class Report:
    """The checks of one participant, the series behind them (for the figure) and the wall time."""

    participant: str
    rows: tuple[Check, ...]
    series: dict = field(repr=False)
    wall_seconds: float = float("nan")
    conditions: dict = field(default_factory=dict)
    """The anatomy variant (build parameters) and the compressive load (N) of the runs."""

    @property
    def passed(self) -> bool:
        return all(r.passed for r in self.rows)

    def row(self, check_id: str) -> Check:
        return next(r for r in self.rows if r.id == check_id)

    def to_dict(self) -> dict:
        """Strict JSON: NaN and ±inf become None (a None band edge means unbounded)."""
        return {
            "participant": self.participant,
            "design": "population",
            "conditions": self.conditions,
            "passed": self.passed,
            "checks": [r.to_dict() for r in self.rows],
            "series": {k: (v if isinstance(v, str) else _list(v)) for k, v in self.series.items()},
            "wall_seconds": _num(round(self.wall_seconds, 3)),
        }


def _num(x):
    x = float(x) + 0.0  # + 0.0: no "-0.0"
    return x if math.isfinite(x) else None


def _list(a):
    return [_num(x) for x in np.asarray(a, dtype=np.float64).ravel()]


# -- measures ------------------------------------------------------------------------------------------------


def slope(x: ArrayLike, y: ArrayLike) -> float:
    """Least-squares slope of y against x over the finite pairs; NaN if x does not vary."""
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    if len(x) < 2 or np.ptp(x) == 0:
        return float("nan")
    dx = x - x.mean()
    return float(dx @ (y - y.mean()) / (dx @ dx))


def surface_gap_mm(
    a_mesh: tuple[ArrayLike, ArrayLike], b_mesh: tuple[ArrayLike, ArrayLike], a_poses: ArrayLike, b_poses: ArrayLike
) -> np.ndarray:
    """Minimum distance (mm) between two posed triangle surfaces at each frame.

    a_mesh, b_mesh: (vertices (n, 3), faces (m, 3)) at the neutral pose; a_poses, b_poses (n_frames, 4, 4)
    neutral → frame. Each surface's vertices are taken into the other's neutral frame and their closest
    points on the other's triangles found (libigl's point–mesh distance); the smaller of both directions.
    0 where the surfaces touch; NaN where a pose is not finite.
    """
    import igl

    meshes = [
        (np.ascontiguousarray(v, dtype=np.float64), np.ascontiguousarray(f, dtype=np.int64))
        for v, f in (a_mesh, b_mesh)
    ]
    a_poses, b_poses = np.asarray(a_poses, dtype=np.float64), np.asarray(b_poses, dtype=np.float64)
    out = np.full(len(a_poses), np.nan)
    for k, (Ta, Tb) in enumerate(zip(a_poses, b_poses)):
        if not (np.isfinite(Ta).all() and np.isfinite(Tb).all()):
            continue
        best = np.inf
        for (pv, _), (qv, qf), rel in (
            (meshes[0], meshes[1], np.linalg.solve(Tb, Ta)),
            (meshes[1], meshes[0], np.linalg.solve(Ta, Tb)),
        ):
            points = np.ascontiguousarray(pv @ rel[:3, :3].T + rel[:3, 3])
            sq, _, _ = igl.point_mesh_squared_distance(points, qv, qf)
            best = min(best, float(np.sqrt(sq.min())))
        out[k] = best
    return out


def sl_gap_mm(model: Model, poses: np.ndarray) -> np.ndarray:
    """Scapholunate gap (mm) per frame of a Result's poses (n_frames, 5, 4, 4): bone surface to bone surface."""
    s, l = BONES.index("scaphoid"), BONES.index("lunate")
    return surface_gap_mm(model.part_mesh("scaphoid"), model.part_mesh("lunate"), poses[:, s], poses[:, l])


def with_tears(d: design_mod.Design, names: Iterable[str]) -> design_mod.Design:
    """A copy of the design with the named injurable ligaments torn (injury scalar −1)."""
    injury = np.array(d.injury, dtype=np.float64)
    for n in names:
        injury[design_mod.INJURABLE.index(n)] = -1.0
    return dataclasses.replace(d, injury=injury)


def at_angle(angle_deg: ArrayLike, values: ArrayLike, target_deg: float) -> float:
    """`values` at the capitate angle `target_deg`, linear between the sweep's frames (NaN outside)."""
    a, v = np.asarray(angle_deg, dtype=np.float64), np.asarray(values, dtype=np.float64)
    order = np.argsort(a)
    a, v = a[order], v[order]
    if not (a[0] <= target_deg <= a[-1]):
        return float("nan")
    return float(np.interp(target_deg, a, v))


# -- the checks ----------------------------------------------------------------------------------------------


def _row(check_id, description, value, band, unit, failed=None) -> Check:
    if failed:
        description = f"{description} [not measured: {failed}]"
        value = float("nan")
    value = float(value)
    passed = math.isfinite(value) and band[0] <= value <= band[1]
    return Check(check_id, description, value, (float(band[0]), float(band[1])), unit, SOURCES[check_id], passed)


def load_shares_pct(model: Model, result) -> dict[str, float]:
    """Load shares (%) at a run's first frame: each midcarpal articulation's (`model.MIDCARPAL`) of their
    sum, and "ulnocarpal": the ulnar path's of radiocarpal + ulnocarpal (NaN for a failed run)."""
    from wrist_env.solver.outputs import articulation_forces

    if not result.ok:
        return {name: math.nan for name in (*MIDCARPAL, "ulnocarpal")}
    f = articulation_forces(model, result.poses[0])
    midcarpal = sum(f[name] for name in MIDCARPAL)
    proximal = f["radioscaphoid"] + f["radiolunate"] + f["ulnocarpal"]
    out = {name: 100.0 * f[name] / midcarpal if midcarpal > 0 else math.nan for name in MIDCARPAL}
    out["ulnocarpal"] = 100.0 * f["ulnocarpal"] / proximal if proximal > 0 else math.nan
    return out


def _failure(label, result) -> str | None:
    return None if result.ok else f"{label} run {result.message}"


def validate(
    name: str,
    *,
    model: Model | None = None,
    d: design_mod.Design | None = None,
    n_frames: int = 17,
    params: BuildParams | None = None,
    load_n: float = IDEALIZED_LOAD_N,
    load_direction: str = DEFAULT_LOADS,
    settings=None,
) -> Report:
    """Run the published-measurement checks on participant `name` (population design by default).

    params: build parameters (`BuildParams`; the anatomy variant), default the default build.
    load_n: the compressive load (N) of the sweeps; the neutral pose takes `NEUTRAL_LOAD_N`.
    load_direction: the loads' direction in the sweeps and at neutral (`simulate.LOAD_DIRECTIONS`).
    settings: the solver's (`arrays.SolverSettings`), default its defaults.
    """
    from wrist_env.builder.pipeline import BuildParams
    from wrist_env.participants.registry import load_model
    from wrist_env.solver import simulate as sim
    from wrist_env.solver.outputs import cardan_deg

    start = time.perf_counter()
    params = params or BuildParams()
    model = model if model is not None else load_model(name, params)
    intact_design = d if d is not None else design_mod.population()
    torn_design = with_tears(intact_design, SLIL)
    direction = load_direction
    sweep = sim.idealized(model, n_frames=n_frames, load_n=load_n, direction=direction)
    intact, torn = sim.simulate_batch(model, [intact_design, torn_design], sweep, settings)
    neutral = sim.simulate(
        model, intact_design, sim.loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N, direction=direction), settings
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
            f"radioscaphoid / radiolunate contact force, capitate held at neutral under {NEUTRAL_LOAD_N:g} N",
            rs_rl,
            (1.1, 2.0),
            "ratio",
            fail_n,
        ),
        *(
            _row(
                f"midcarpal_{key}_share_pct",
                f"{name}'s share of the midcarpal contact force, neutral, {NEUTRAL_LOAD_N:g} N",
                shares[name],
                (pct - 10.0, pct + 10.0),
                "%",
                fail_n,
            )
            for (key, pct), name in zip(VIEGAS_1993.items(), MIDCARPAL)
        ),
        _row(
            "ulnar_share_pct",
            f"ulnocarpal share of the radiocarpal + ulnocarpal contact force, neutral, {NEUTRAL_LOAD_N:g} N",
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


# -- output --------------------------------------------------------------------------------------------------


def _fmt(x: float) -> str:
    return f"{x:.3g}" if math.isfinite(x) else str(x)


def format_table(report: Report) -> str:
    """The checks as a plain-text table: check, value, band, unit, pass/FAIL, source."""
    c = report.conditions
    lines = [
        f"{report.participant}, population design: the model against published measurements"
        + (
            f" (fossa sweep ±{c['fossa_sweep_deg']} deg, distal row {'on' if c['distal_row'] else 'off'}, "
            f"TC/TH {'on' if c.get('fixed_ligaments') else 'off'}, sweep load {c['load_n']:g} N, "
            f"load direction {c.get('load_direction', 'axial')})"
            if c
            else ""
        ),
        f"{'check':<24} {'value':>8}  {'band':<13} {'unit':<8} {'result':<6}  source",
    ]
    for r in report.rows:
        band = f"{_fmt(r.band[0])}-{_fmt(r.band[1])}" if math.isfinite(r.band[1]) else f"> {_fmt(r.band[0])}"
        lines.append(
            f"{r.id:<24} {_fmt(r.value):>8}  {band:<13} {r.unit:<8} {'pass' if r.passed else 'FAIL':<6}  "
            f"{r.source.split(' (')[0]}"
        )
    for r in report.rows:
        if "[not measured" in r.description:
            lines.append(f"{r.id}: {r.description}")
    n = sum(r.passed for r in report.rows)
    lines.append(f"{n}/{len(report.rows)} checks pass; {report.wall_seconds:.1f} s")
    return "\n".join(lines)


def validation_figure(report: Report, out: Path | None = None) -> Path:
    """Left: scaphoid and lunate flexion against the capitate's, with the model's slopes and Rainbow 2013's
    ratios; right: the SL gap over the sweep, intact and with all SLIL bundles torn, and the 3 mm line."""
    import matplotlib.pyplot as plt

    from wrist_env.figures.draw import FIGURES

    out = Path(out) if out else FIGURES / f"validation_{report.participant}.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    s = report.series
    cap = np.asarray(s["capitate_flexion_deg"], dtype=float)
    angle = np.asarray(s["capitate_angle_deg"], dtype=float)
    colours = {"scaphoid": "#1f77b4", "lunate": "#d62728"}
    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 5.6), gridspec_kw=dict(width_ratios=(1.1, 1)))
    lim = float(np.nanmax(np.abs(angle))) + 3
    xs = np.array([-lim, lim])
    for bone, check, ref in (
        ("scaphoid", "scaphoid_slope", RAINBOW_SCAPHOID),
        ("lunate", "lunate_slope", RAINBOW_LUNATE),
    ):
        y = np.asarray(s[f"{bone}_flexion_deg"], dtype=float)
        k = report.row(check).value
        left.plot(cap, y, "o", color=colours[bone], ms=4, label=f"{bone}, model")
        if math.isfinite(k):
            ok = np.isfinite(cap) & np.isfinite(y)
            b0 = float(np.mean(y[ok]) - k * np.mean(cap[ok]))
            left.plot(xs, k * xs + b0, "-", color=colours[bone], lw=1.5, label=f"{bone}, model slope {k:.2f}")
        left.plot(
            xs, ref * xs, "--", color=colours[bone], lw=1.2, alpha=0.7, label=f"{bone}, Rainbow 2013 ratio {ref:.2f}"
        )
    left.plot(xs, xs, ":", color="0.6", lw=1, label="identity (moves with the capitate)")
    left.axhline(0, color="0.85", lw=0.8, zorder=0)
    left.axvline(0, color="0.85", lw=0.8, zorder=0)
    left.set_xlim(-lim, lim)
    left.set_ylim(-lim, lim)
    left.set_aspect("equal")
    left.set_xlabel("capitate flexion (+) / extension (−), deg")
    left.set_ylabel("bone flexion (+) / extension (−), deg")
    left.set_title("proximal row following the capitate")
    left.legend(loc="upper left", fontsize=8)

    g_i, g_t = np.asarray(s["sl_gap_intact_mm"], dtype=float), np.asarray(s["sl_gap_slil_torn_mm"], dtype=float)
    right.plot(angle, g_i, "o-", color="0.2", ms=4, label="intact")
    right.plot(angle, g_t, "s-", color="#d62728", ms=4, label="SLIL_v + SLIL_p + SLIL_d torn")
    right.axhline(SL_DISSOCIATION_MM, color="#ff7f0e", ls="--", lw=1.2, label="3 mm gap: clinical SL dissociation")
    right.axhspan(
        6.6 - 1.6, 6.6 + 1.6, color="#ff7f0e", alpha=0.12, lw=0, label="Haug 2021: 6.6 ± 1.6 mm after SLIL transection"
    )
    growth = report.row("sl_gap_growth_mm")
    notes = [
        f"check: torn − intact at full extension {_fmt(growth.value)} mm "
        f"(band > {_fmt(growth.band[0])} mm): {'pass' if growth.passed else 'FAIL'}"
    ]
    notes += [f"{k}: {s[k]}" for k in ("intact_status", "slil_torn_status") if s.get(k) != "ok"]
    right.text(
        0.98,
        0.37,
        "\n".join(notes),
        transform=right.transAxes,
        ha="right",
        va="center",
        fontsize=9,
        bbox=dict(boxstyle="round", fc="white", ec="0.8"),
    )
    right.set_xlim(lim, -lim)  # flexion on the left, extension on the right: the sweep's direction
    top = np.nanmax(np.concatenate([g_i, g_t, [9.5]]))
    right.set_ylim(0, float(top) * 1.12)
    right.set_xlabel("capitate angle, deg (flexion + → extension −)")
    right.set_ylabel("scapholunate gap, mm (closest bone surfaces)")
    right.set_title("SL gap over the idealized sweep")
    right.legend(loc="upper left", fontsize=8)
    n = sum(r.passed for r in report.rows)
    fig.suptitle(
        f"{report.participant}, population design: {n}/{len(report.rows)} published-measurement checks pass",
        fontsize=12,
    )
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


__all__ = [
    "Check",
    "Report",
    "format_table",
    "sl_gap_mm",
    "slope",
    "surface_gap_mm",
    "validate",
    "validation_figure",
    "with_tears",
]
