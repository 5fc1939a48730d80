"""A validation report: its checks (strict JSON), the table and the figure."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from wrist_env.figures.draw import FIGURES, note_box
from wrist_env.validation.bands import RAINBOW_LUNATE, RAINBOW_SCAPHOID, SL_DISSOCIATION_MM, SOURCES


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


def _row(check_id, description, value, band, unit, failed=None) -> Check:
    if failed:
        description = f"{description} [not measured: {failed}]"
        value = float("nan")
    value = float(value)
    passed = math.isfinite(value) and band[0] <= value <= band[1]
    return Check(check_id, description, value, (float(band[0]), float(band[1])), unit, SOURCES[check_id], passed)


def _fmt(x: float) -> str:
    return f"{x:.3g}" if math.isfinite(x) else str(x)


def band_text(low: float, high: float) -> str:
    """A published band as the tables print it: "low-high", or "> low" when it has no upper edge (inf)."""
    return f"{_fmt(low)}-{_fmt(high)}" if math.isfinite(high) else f"> {_fmt(low)}"


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
        lines.append(
            f"{r.id:<24} {_fmt(r.value):>8}  {band_text(*r.band):<13} {r.unit:<8} {'pass' if r.passed else 'FAIL':<6}  "
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
    note_box(right, notes, 0.37, "center")
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
