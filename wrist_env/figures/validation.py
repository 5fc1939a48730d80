"""The validation report's figure (`wrist-bench validate`): the proximal row following the capitate and
the SL gap over the sweep, intact and with the SLIL torn."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from wrist_env.figures.draw import FIGURES, note_box
from wrist_env.validation.bands import RAINBOW_LUNATE, RAINBOW_SCAPHOID, SL_DISSOCIATION_MM
from wrist_env.validation.report import Report, _fmt


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
