"""Figures of a Bayesian calibration (`wrist_env.identification.bayes`): credible intervals of the 22 materials
against the hidden truth, and the posterior predictive kinematics of both trials (PNG)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from wrist_env import design
from wrist_env.cost import COST_BONES
from wrist_env.figures.draw import save
from wrist_env.frames import DOF_NAMES, DOF_UNITS

PRIOR_90 = 1.645  # the N(0, 1) prior's 90 % interval, z units


def plot_intervals(posteriors, truth: np.ndarray | None, out: str | Path) -> Path:
    """One row per material: each run's 50 % (thick) and 90 % (thin) interval and median, the prior's
    90 % band (grey) and the hidden truth (red)."""
    names = design.NAMES[: design.N_MATERIAL]
    fig, ax = plt.subplots(figsize=(8, 9.5))
    ax.axvspan(-PRIOR_90, PRIOR_90, color="0.92", label="prior 90 %")
    k = len(posteriors)
    for j, post in enumerate(posteriors):
        q = post.quantiles((0.05, 0.25, 0.5, 0.75, 0.95))
        y = np.arange(len(names)) + (j - (k - 1) / 2) * 0.22
        colour = plt.cm.tab10(j)
        ax.hlines(y, q[0], q[4], color=colour, lw=1)
        ax.hlines(y, q[1], q[3], color=colour, lw=4, label=f"seed {post.seed}: 50 % / 90 %")
        ax.plot(q[2], y, "|", color="k", ms=6)
    if truth is not None:
        ax.plot(truth, np.arange(len(names)), "x", color="tab:red", ms=8, mew=2, label="hidden truth")
    ax.set_yticks(range(len(names)), names, fontsize=8)
    ax.invert_yaxis()
    ax.set(xlabel="z (Table 2 SD from the mean)", xlim=(-3.1, 3.1))
    ax.legend(loc="lower right", fontsize=8)
    which = "calibration trial" if posteriors[0].trials == "built-in" else "the model's own run of the truth + noise"
    ax.set_title(f"{posteriors[0].participant}: posterior credible intervals ({which})")
    fig.tight_layout()
    return save(fig, out)


def plot_predictive(post, out: str | Path) -> Path:
    """Rows: calibration trial scaphoid, lunate, held-out trial scaphoid, lunate; columns: the six DOF.
    The 5–95 % band and median of the model's kinematics over posterior draws (the materials'
    uncertainty; tracking noise not added) against the trial's frames."""
    fig, axes = plt.subplots(4, 6, figsize=(17, 10), sharex=True)
    frames = np.arange(post.observed.shape[2])
    for m, motion in enumerate(("calibration", "held-out")):
        for b, bone in enumerate(COST_BONES):
            row = 2 * m + b
            for d, (dof, unit) in enumerate(zip(DOF_NAMES, DOF_UNITS)):
                ax = axes[row, d]
                lo, mid, hi = post.predictive[m, :, b, :, d]
                ax.fill_between(frames, lo, hi, color="tab:blue", alpha=0.3, lw=0)
                ax.plot(frames, mid, color="tab:blue", lw=1.2)
                ax.plot(frames, post.observed[m, b, :, d], "k.", ms=4)
                if row == 0:
                    ax.set_title(f"{dof} ({unit})", fontsize=9)
                if d == 0:
                    ax.set_ylabel(f"{motion}\n{bone}", fontsize=9)
                if row == 3:
                    ax.set_xlabel("frame")
                ax.tick_params(labelsize=7)
    fig.suptitle(
        f"{post.participant}: the model's kinematics over the posterior (5–95 % band, median; the materials' "
        f"uncertainty, tracking noise not added; dots: the {'trial' if post.trials == 'built-in' else 'model trial'}), "
        f"seed {post.seed}"
    )
    fig.tight_layout()
    return save(fig, out, dpi=100)
