"""What every figure shares: the output folder, colours, the RCS-to-plot axes, mesh drawing."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from numpy.typing import ArrayLike

from wrist_env.ligaments import ALL_LIGAMENT_NAMES

if TYPE_CHECKING:
    from matplotlib.typing import ColorType
    from mpl_toolkits.mplot3d import Axes3D

FIGURES = Path(os.environ.get("WRIST_ENV_FIGURES", Path("runs") / "figures"))
"""Default folder of every figure: `$WRIST_ENV_FIGURES`, else runs/figures under the working directory
(never the committed figures in experiments/figures, which the docs show: `experiments/regenerate.py` writes those)."""
BONE_COLOUR = {
    "radius": "#d9cfc1",
    "ulna": "#d9cfc1",
    "scaphoid": "#e8dcc8",
    "lunate": "#e3d5bd",
    "capitate": "#eadfcf",
    "trapezium": "#e6d9c4",
    "hamate": "#e1d3bf",
}
DISTAL_CROP_MM = 12.0  # radius and ulna are drawn by their distal end only (RCS y below this, mm)
LIGAMENT_COLOURS = dict(
    zip(
        ALL_LIGAMENT_NAMES,
        plt.get_cmap("tab10").colors
        + ("#000000", "#7a5195", "#ef5675", "#ffa600", "#003f5c", "#58508d", "#bc5090", "#2f4b7c", "#a05195"),
    )
)


def save(fig, out: str | Path, dpi: int = 110, **kwargs) -> Path:
    """Write `fig` as a PNG at `out` (folders created), close it, return the path."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=dpi, **kwargs)
    plt.close(fig)
    return out


def note_box(ax, lines: list[str], y: float, va: str, **text) -> None:
    """`lines` in a rounded white box at the right edge of `ax`, at height `y` (axes fraction)."""
    ax.text(
        0.98, y, "\n".join(lines), transform=ax.transAxes, ha="right", va=va, fontsize=9,
        bbox=dict(boxstyle="round", fc="white", ec="0.8"), **text,
    )  # fmt: skip


def to_plot(p: ArrayLike) -> np.ndarray:
    """RCS (x volar, y proximal, z radial) to plot axes (radial right, volar towards the viewer, proximal up)."""
    p = np.asarray(p)
    return np.stack([p[..., 2], -p[..., 0], p[..., 1]], axis=-1)


def add_mesh(
    ax: Axes3D,
    vertices: np.ndarray,
    faces: np.ndarray,
    colour: ColorType | None,
    alpha: float = 1.0,
    facecolors: ArrayLike | None = None,
) -> None:
    tris = to_plot(vertices[faces])
    coll = Poly3DCollection(
        tris,
        facecolors=facecolors if facecolors is not None else colour,
        linewidths=0,
        alpha=alpha,
        shade=True,
        lightsource=matplotlib.colors.LightSource(45, 45),
    )
    ax.add_collection3d(coll)


def frame_axes(ax: Axes3D, points: ArrayLike, title: str) -> None:
    p = to_plot(points)
    centre = (p.max(axis=0) + p.min(axis=0)) / 2
    half = (p.max(axis=0) - p.min(axis=0)).max() / 2
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        setter(c - half, c + half)
    ax.set_box_aspect((1, 1, 1), zoom=1.3)
    ax.set_xlabel("radial (mm)")
    ax.set_ylabel("dorsal (mm)")
    ax.set_zlabel("proximal (mm)")
    ax.set_title(title)


def crop(vertices: np.ndarray, faces: np.ndarray, y_max: float) -> np.ndarray:
    return faces[(vertices[faces][:, :, 1] < y_max).all(axis=1)]
