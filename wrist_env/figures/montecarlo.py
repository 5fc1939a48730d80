"""Figures 8–10 of the Monte Carlo study (PNG, matplotlib), from `montecarlo.stats.frame_table` rows and
what the report computes from its fits (`TearEstimates`); nothing here fits or imports the study.

figure8: radioscaphoid mean pressure against the wrist angle — (A) every run
    as dots (a seeded subset when there are many), the per-angle medians of
    intact runs and of runs with at least one tear; (B) Table 5's estimated
    sweep-average pressure with each ligament torn alone (95 % CI), over the
    sweep averages of the runs with that tear.
figure9: radioscaphoid mean pressure at full extension (the sweep's last
    frame) for intact runs, partial SLIL tears (one or two SLIL bundles, RSC
    and LRL intact), full SLIL tears (all three bundles, RSC and LRL intact)
    and any injury, per participant.
figure10: SLIL bundle forces against the wrist angle in intact runs: dots and
    per-angle medians, per participant.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from wrist_env.ligaments import INJURABLE

INTACT_COLOR, INJURED_COLOR = "#d6609a", "#3b6fb6"  # the preprint's pink and blue
BUNDLE_COLORS = {"SLIL_v": "#2a9d8f", "SLIL_p": "#e9a23b", "SLIL_d": "#6a4c93"}
ANGLE_LABEL = "wrist angle (°): extension − / flexion +"
MAX_DOT_RUNS = 300


@dataclass(frozen=True)
class TearEstimates:
    """Figure 8 (B)'s estimates: Table 5's sweep-average radioscaphoid pressure intact and with each ligament
    torn alone (`montecarlo.report.tear_estimates`).

    tears: None (intact), then the tear columns of the frame table (`ligaments.INJURABLE`), one per estimate;
    labels: their tick labels; estimate_mpa, se_mpa (len(tears),): the estimate and its standard error, MPa."""

    tears: tuple[str | None, ...]
    labels: tuple[str, ...]
    estimate_mpa: tuple[float, ...]
    se_mpa: tuple[float, ...]


def _dot_runs(frames: pd.DataFrame, limit: int = MAX_DOT_RUNS, seed: int = 0) -> pd.DataFrame:
    groups = frames["group"].unique()
    if len(groups) <= limit:
        return frames
    keep = np.random.default_rng(seed).choice(groups, size=limit, replace=False)
    return frames[frames["group"].isin(set(keep))]


def _jitter(x, width: float, seed: int = 0):
    return np.asarray(x, float) + np.random.default_rng(seed).uniform(-width, width, len(x))


def _angle_axis(ax):
    ax.set_xlabel(ANGLE_LABEL)
    ax.axvline(0.0, color="0.85", lw=0.8, zorder=0)
    ax.grid(True, axis="y", color="0.92")


def figure8(frames: pd.DataFrame, tears: TearEstimates, out: str | Path) -> Path:
    """(A) per participant: every run's radioscaphoid pressure against the angle and the per-angle medians,
    intact and injured; (B) `tears`' estimates ± 95 % CI over the sweep averages of the runs with each tear."""
    participants = sorted(frames["participant"].unique())
    fig, axes = plt.subplots(
        1,
        len(participants) + 1,
        figsize=(4.6 * (len(participants) + 1), 4.4),
        gridspec_kw={"width_ratios": [1.0] * len(participants) + [1.1]},
    )
    top = float(np.nanpercentile(frames["rs_mean_mpa"], 99.5)) * 1.08
    for ax, name in zip(axes, participants):
        part = frames[frames["participant"] == name]
        dots = _dot_runs(part)
        for injured, color in ((1, INJURED_COLOR), (0, INTACT_COLOR)):  # intact (fewer) on top
            d = dots[dots["any_injury"] == injured]
            ax.scatter(_jitter(d["angle"], 1.2, injured), d["rs_mean_mpa"], s=4, color=color, alpha=0.25, lw=0)
        for injured, color, label in ((0, INTACT_COLOR, "intact"), (1, INJURED_COLOR, "≥ 1 ligament torn")):
            med = part[part["any_injury"] == injured].groupby("angle")["rs_mean_mpa"].median()
            n = part.loc[part["any_injury"] == injured, "group"].nunique()
            ax.plot(med.index, med.to_numpy(), color=color, lw=2.4, label=f"median, {label} (n = {n})")
        ax.set_title(f"(A) {name}: radioscaphoid pressure", fontsize=10)
        _angle_axis(ax)
        ax.set_ylabel("mean radioscaphoid pressure (MPa)")
        ax.set_ylim(0.0, top)
        ax.legend(fontsize=8, loc="upper right")

    ax = axes[-1]
    run_mean = frames.groupby("group").agg(
        rs=("rs_mean_mpa", "mean"), any=("any_injury", "max"), **{lig: (lig, "max") for lig in INJURABLE}
    )
    labels = list(tears.labels)
    for i, (key, est, se) in enumerate(zip(tears.tears, tears.estimate_mpa, tears.se_mpa)):
        runs = run_mean[run_mean["any"] == 0] if key is None else run_mean[run_mean[key] == 1]
        runs = runs.sample(min(len(runs), MAX_DOT_RUNS), random_state=i) if len(runs) else runs
        color = INTACT_COLOR if key is None else INJURED_COLOR
        ax.scatter(_jitter(np.full(len(runs), i), 0.22, i), runs["rs"], s=5, color=color, alpha=0.35, lw=0)
        ax.errorbar([i], [est], yerr=[1.96 * se], fmt="o", color="k", ms=6, capsize=5, lw=1.6, zorder=5)
        ax.annotate(f"{est:.2f}", (i, est), xytext=(9, -3), textcoords="offset points", fontsize=8)
    ax.set_xticks(range(len(labels)), labels, rotation=30, ha="right")
    ax.set_xlim(-0.6, len(labels) - 0.4)
    ax.set_ylim(0.0, float(np.nanpercentile(run_mean["rs"], 99.5)) * 1.1)
    ax.set_ylabel("sweep-average radioscaphoid pressure (MPa)")
    ax.set_title(
        "(B) mixed-model estimate, ligament torn alone\n(black: estimate ± 95 % CI; dots: runs with the tear)",
        fontsize=9,
    )
    ax.grid(True, axis="y", color="0.92")
    fig.tight_layout()
    return _save(fig, out)


def figure9(at: pd.DataFrame, groups: tuple[str, ...], out: str | Path) -> Path:
    """Radioscaphoid pressure at full extension per injury group (`groups`: the `category` values of `at`,
    then "Any injury", runs with any tear), a box per participant: `at` is the runs' rows at full
    extension with their category (`montecarlo.stats.full_extension`)."""
    participants = sorted(at["participant"].unique())
    colors = ["#3b6fb6", "#e07b39", "#4f9d69"]
    fig, ax = plt.subplots(figsize=(7.6, 4.6))
    width = 0.8 / len(participants)
    for j, name in enumerate(participants):
        part = at[at["participant"] == name]
        data = [
            part.loc[part["category"] == g, "rs_mean_mpa"].to_numpy()
            if g != "Any injury"
            else part.loc[part["any_injury"] == 1, "rs_mean_mpa"].to_numpy()
            for g in groups
        ]
        pos = np.arange(len(groups)) + (j - (len(participants) - 1) / 2) * width
        keep = [k for k, d in enumerate(data) if len(d)]
        bp = ax.boxplot(
            [data[k] for k in keep],
            positions=pos[keep],
            widths=width * 0.85,
            patch_artist=True,
            showfliers=False,
            medianprops={"color": "k"},
        )
        for box in bp["boxes"]:
            box.set(facecolor=colors[j % len(colors)], alpha=0.45)
        for k in keep:
            d = data[k]
            d = d if len(d) <= MAX_DOT_RUNS else np.random.default_rng(k).choice(d, MAX_DOT_RUNS, replace=False)
            ax.scatter(
                _jitter(np.full(len(d), pos[k]), width * 0.3, k), d, s=3, color=colors[j % len(colors)], alpha=0.3, lw=0
            )
        ax.plot([], [], "s", color=colors[j % len(colors)], alpha=0.6, label=name)
    counts = [
        ", ".join(
            f"{n}: {int(((at['participant'] == n) & ((at['category'] == g) if g != 'Any injury' else (at['any_injury'] == 1))).sum())}"
            for n in participants
        )
        for g in groups
    ]
    ax.set_xticks(range(len(groups)), [f"{g}\n({c})" for g, c in zip(groups, counts)], fontsize=8)
    ax.set_ylabel("mean radioscaphoid pressure (MPa)")
    ax.set_title(
        f"Radioscaphoid pressure at full extension ({-at['angle'].min():.0f}°); boxes 25–75 %, whiskers 1.5 IQR",
        fontsize=9,
    )
    ax.set_ylim(0.0, float(np.nanpercentile(at["rs_mean_mpa"], 99.5)) * 1.1)
    ax.grid(True, axis="y", color="0.92")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, out)


def figure10(frames: pd.DataFrame, bundles: dict[str, str], out: str | Path) -> Path:
    """SLIL bundle forces against the angle in intact runs, dots and per-angle medians, a panel per
    participant; bundles: the bundles drawn, column stem ("SLIL_v", its `<stem>.force_n`) -> label."""
    intact = frames[frames["any_injury"] == 0]
    participants = sorted(intact["participant"].unique())
    fig, axes = plt.subplots(1, len(participants), figsize=(4.8 * len(participants), 4.2), sharey=True, squeeze=False)
    top = max(float(np.nanpercentile(intact[[f"{l}.force_n" for l in bundles]].to_numpy(), 99.5)) * 1.08, 1.0)
    for ax, name in zip(axes[0], participants):
        part = intact[intact["participant"] == name]
        dots = _dot_runs(part)
        for k, lig in enumerate(bundles):
            ax.scatter(
                _jitter(dots["angle"] + (k - 1) * 1.2, 0.5, k),
                dots[f"{lig}.force_n"],
                s=4,
                color=BUNDLE_COLORS[lig],
                alpha=0.3,
                lw=0,
            )
        for lig in bundles:
            med = part.groupby("angle")[f"{lig}.force_n"].median()
            ax.plot(med.index, med.to_numpy(), color=BUNDLE_COLORS[lig], lw=2.4, label=f"{bundles[lig]} median")
        ax.set_title(f"{name}: SLIL bundle forces, intact runs (n = {part['group'].nunique()})", fontsize=10)
        _angle_axis(ax)
        ax.set_ylim(0.0, top)
        ax.legend(fontsize=8, loc="upper right")
    axes[0][0].set_ylabel("bundle force (N)")
    fig.tight_layout()
    return _save(fig, out)


def _save(fig, out) -> Path:
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=130)
    plt.close(fig)
    return out
