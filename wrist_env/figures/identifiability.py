"""Figure of what a trial identifies (`wrist_env.identification.fisher`): the Fisher spectrum and the
per-material posterior SD for the calibration trial, the held-out trial and both (PNG)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from wrist_env.figures.draw import save

COLOURS = {"calibrate": "tab:blue", "validate": "tab:orange", "both": "tab:green"}


def plot(materials: pd.DataFrame, spectra: pd.DataFrame, participant: str, out: str | Path) -> Path:
    """Left: SD to which each eigen-direction is pinned (log); right: each material's posterior SD."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 5.5), gridspec_kw={"width_ratios": [1, 2]})
    for trials, colour in COLOURS.items():
        s = spectra[(spectra["participant"] == participant) & (spectra["trials"] == trials)]
        sd = np.clip(s["sd"].to_numpy(), 1e-3, 1e3)
        left.semilogy(s["direction"], sd, "o-", color=colour, label=trials, ms=4)
        m = materials[(materials["participant"] == participant) & (materials["trials"] == trials)]
        k = list(COLOURS).index(trials)
        right.bar(np.arange(len(m)) + (k - 1) * 0.27, m["posterior_sd"], width=0.27, color=colour, label=trials)
    left.axhline(1.0, color="k", lw=0.8, ls="--")
    left.set(xlabel="eigen-direction (most informed first)", ylabel="SD pinned to (z units; 1 = the prior)")
    left.legend(title="trials")
    names = materials[(materials["participant"] == participant) & (materials["trials"] == "both")]["material"]
    right.set_xticks(range(len(names)), names, rotation=90, fontsize=8)
    right.axhline(1.0, color="k", lw=0.8, ls="--")
    right.set(ylabel="posterior SD with the Table 2 prior (z units)", ylim=(0, 1.05))
    fig.suptitle(f"{participant}: what the trials identify at the hidden truth (Fisher, 4DCT noise 0.2 mm / 0.5°)")
    fig.tight_layout()
    return save(fig, out)
