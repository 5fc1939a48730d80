"""The validation report's figure (`wrist-bench validate`): the proximal row following the capitate and
the SL gap over the sweep, intact and with the SLIL torn."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from wrist_env.figures.draw import FIGURES, note_box


@dataclass(frozen=True)
class ValidationPanels:
    """What the validation figure draws (`wrist_env.validation.report.figure_panels` makes it from a report).

    series: the sweep's arrays (n_frames,) by name: capitate_flexion_deg, capitate_angle_deg,
        scaphoid_flexion_deg, lunate_flexion_deg, sl_gap_intact_mm, sl_gap_slil_torn_mm.
    slopes: the model's flexion slope per bone (deg/deg; NaN when not measured); ratios: the published ratio
        per bone (Rainbow 2013). dissociation_mm: the clinical SL dissociation line; torn_gap_mm: a published
        gap after SLIL transection (mean, SD; Haug 2021). notes: the lines of the note box. passed, total: the
        checks that pass, of all.
    """

    participant: str
    series: dict
    slopes: dict
    ratios: dict
    dissociation_mm: float
    torn_gap_mm: tuple[float, float]
    notes: list
    passed: int
    total: int


def validation_figure(panels: ValidationPanels, out: Path | None = None) -> Path:
    """Left: scaphoid and lunate flexion against the capitate's, with the model's slopes and Rainbow 2013's
    ratios; right: the SL gap over the sweep, intact and with all SLIL bundles torn, and the 3 mm line."""
    import matplotlib.pyplot as plt

    out = Path(out) if out else FIGURES / f"validation_{panels.participant}.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    s = panels.series
    cap = np.asarray(s["capitate_flexion_deg"], dtype=float)
    angle = np.asarray(s["capitate_angle_deg"], dtype=float)
    colours = {"scaphoid": "#1f77b4", "lunate": "#d62728"}
    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 5.6), gridspec_kw=dict(width_ratios=(1.1, 1)))
    lim = float(np.nanmax(np.abs(angle))) + 3
    xs = np.array([-lim, lim])
    for bone in ("scaphoid", "lunate"):
        y = np.asarray(s[f"{bone}_flexion_deg"], dtype=float)
        k, ref = panels.slopes[bone], panels.ratios[bone]
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
    line = panels.dissociation_mm
    right.axhline(line, color="#ff7f0e", ls="--", lw=1.2, label=f"{line:g} mm gap: clinical SL dissociation")
    mean, sd = panels.torn_gap_mm
    right.axhspan(
        mean - sd,
        mean + sd,
        color="#ff7f0e",
        alpha=0.12,
        lw=0,
        label=f"Haug 2021: {mean:g} ± {sd:g} mm after SLIL transection",
    )
    note_box(right, panels.notes, 0.37, "center")
    right.set_xlim(lim, -lim)  # flexion on the left, extension on the right: the sweep's direction
    top = np.nanmax(np.concatenate([g_i, g_t, [9.5]]))
    right.set_ylim(0, float(top) * 1.12)
    right.set_xlabel("capitate angle, deg (flexion + → extension −)")
    right.set_ylabel("scapholunate gap, mm (closest bone surfaces)")
    right.set_title("SL gap over the idealized sweep")
    right.legend(loc="upper left", fontsize=8)
    fig.suptitle(
        f"{panels.participant}, population design: {panels.passed}/{panels.total} published-measurement checks pass",
        fontsize=12,
    )
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
