"""Figure of a sensitivity study (`wrist_env.identification.sensitivity`): materials × outputs, a panel per motion (PNG)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from wrist_env.figures.draw import save

SHADE = {"morris": ("mu_star", "Morris μ* / largest μ* of the output"), "sobol": ("ST", "Sobol total index ST")}


def plot(table: pd.DataFrame, method: str, out: str | Path) -> Path:
    """Heat maps of each material's index (rows) for each output (columns), one panel per motion."""
    column, label = SHADE[method]
    motions = list(dict.fromkeys(table["motion"]))
    materials = list(dict.fromkeys(table["material"]))
    outputs = list(dict.fromkeys(table["output"]))
    fig, axes = plt.subplots(1, len(motions), figsize=(4.2 * len(motions) + 1.5, 7.5), squeeze=False)
    for ax, motion in zip(axes[0], motions):
        rows = table[table["motion"] == motion]
        grid = rows.pivot(index="material", columns="output", values=column).loc[materials, outputs].to_numpy()
        if method == "morris":
            grid = grid / np.maximum(grid.max(axis=0, keepdims=True), 1e-12)
        image = ax.imshow(np.clip(grid, 0.0, 1.0), cmap="viridis", vmin=0.0, vmax=1.0, aspect="auto")
        runs, failed = int(rows["runs"].iloc[0]), rows["failed_share"].iloc[0]
        ax.set_title(f"{motion} ({runs} runs, {failed:.0%} failed)")
        ax.set_xticks(range(len(outputs)), [o.replace("scaphoid.", "S ").replace("lunate.", "L ") for o in outputs])
        ax.tick_params(axis="x", rotation=90, labelsize=7)
        ax.set_yticks(range(len(materials)), materials if ax is axes[0][0] else [""] * len(materials), fontsize=7)
    fig.colorbar(image, ax=axes[0].tolist(), shrink=0.6, label=label)
    participant = table["participant"].iloc[0]
    fig.suptitle(f"{participant}: sensitivity of the cost and the scaphoid (S) and lunate (L) DOF errors")
    return save(fig, out, bbox_inches="tight")
