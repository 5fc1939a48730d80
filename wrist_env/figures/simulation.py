"""Figures of simulations: contact pressure at neutral (preprint Figure 3) and the row's kinematics.

Pictures take data: a `PressureFrame` and `RowKinematics` hold what was simulated (`cli.run.figure_data`
simulates it); nothing here loads a participant or runs the solver."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from wrist_env.figures import draw
from wrist_env.model import BONES, PAIR_BONES, PAIRS, Model


@dataclass(frozen=True)
class PressureFrame:
    """One simulated frame of a participant's model, as the pressure figure draws it.

    name: the participant; poses (n_bodies, 4, 4): each body's pose (RCS, mm); pressure_mpa (n_samples,):
    each contact sample's pressure, MPa, in `model.sample_points` order (0 out of contact); contact
    (n_pairs, 4): per pair (`PAIRS`) mean and peak pressure (MPa), area (mm²) and force (N); samples: each
    drawn pair's slice of the samples; how: the frame's driver and load, in words (the subtitle)."""

    name: str
    poses: np.ndarray
    pressure_mpa: np.ndarray
    contact: np.ndarray
    samples: dict[str, slice]
    how: str


@dataclass(frozen=True)
class RowKinematics:
    """One design's run through a sweep, as the kinematics figure draws it.

    label: the design ("population", "hidden truth"); style: its line style; angles_deg (n_frames, n_bodies,
    3): each body's Cardan Z-X-Y angles (deg) at each frame, None when the run failed; message: why it
    failed ("" when it did not)."""

    label: str
    style: str
    angles_deg: np.ndarray | None
    message: str = ""


def _silhouette(ax, points_2d, colour, *, spacing=0.2, radius=1.0, filled=False, **kw):
    """Outline (or filled region) of a projected point cloud: the points dilated by `radius` mm on a
    raster, smoothed, contoured at one half."""
    from scipy.ndimage import gaussian_filter
    from scipy.spatial import cKDTree

    lo, hi = points_2d.min(axis=0) - 3 * radius, points_2d.max(axis=0) + 3 * radius
    gx, gy = np.arange(lo[0], hi[0], spacing), np.arange(lo[1], hi[1], spacing)
    X, Y = np.meshgrid(gx, gy)
    d, _ = cKDTree(points_2d).query(np.column_stack([X.ravel(), Y.ravel()]), distance_upper_bound=radius)
    inside = gaussian_filter(np.isfinite(d).reshape(X.shape).astype(float), 0.5 / spacing)
    if filled:
        return ax.contourf(X, Y, inside, levels=[0.5, 2.0], colors=[colour], **kw)
    return ax.contour(X, Y, inside, levels=[0.5], colors=[colour], **kw)


def _mpa(value) -> str:
    return f"{value:.2f} MPa" if value >= 0.01 or value == 0 else f"{value:.1e} MPa"


def _world(poses_frame, bone_index, points):
    P = poses_frame[bone_index]
    return points @ P[:3, :3].T + P[:3, 3]


PRESSURE_PANELS = (
    # title, pairs, bones pressed on (filled, with their cartilage), bones pressing (dashed outlines)
    (
        "radiocarpal: scaphoid and lunate samples on the radius",
        ("radioscaphoid", "radiolunate"),
        ("radius", "ulna"),
        ("scaphoid", "lunate"),
    ),
    (
        "midcarpal: capitate-head samples on the scaphoid and lunate",
        ("scaphocapitate", "lunocapitate"),
        ("scaphoid", "lunate"),
        ("capitate",),
    ),
)
_BONE_FILL, _CARTILAGE_FILL, _OUTLINE = "#e6e1d8", "#c9d3de", "#4d4d4d"


def pressure_figure(model: Model, frame: PressureFrame, out: Path | None = None) -> Path:
    """Draw the contact pressure at the neutral pose, viewed from distal (preprint Figure 3's pressure plot).

    Samples are drawn at their world positions projected on the RCS x–z plane (radial to the right, volar
    down: the view from distal, not mirrored).

    Parameters
    ----------
    model : Model
        The participant's model (its bone meshes and contact samples).
    frame : PressureFrame
        The population design's frame at neutral, simulated (`cli.run.figure_data.pressure_frame`: the 0°
        frame of the idealized ±40° sweep, or the capitate held at neutral): poses of shape
        (n_bodies, 4, 4), mm; pressure per sample of shape (n_samples,), MPa.
    out : Path, optional
        The PNG's path (default ``FIGURES / "pressure_<name>.png"``).

    Returns
    -------
    Path
        The PNG's path.
    """
    from scipy.spatial import cKDTree

    name = frame.name
    out = out or draw.FIGURES / f"pressure_{name}.png"
    poses, pressure, how = frame.poses, frame.pressure_mpa, frame.how
    shown = [p for _, pairs, _, _ in PRESSURE_PANELS for p in pairs]
    peak = max(float(pressure[frame.samples[p]].max()) for p in shown)
    norm = matplotlib.colors.Normalize(0.0, max(peak, 1e-3))
    cmap = plt.get_cmap("turbo")

    def xz(world):  # plot coordinates: radial (RCS z) right; RCS x (volar) down once the axis is inverted
        return np.column_stack([world[:, 2], world[:, 0]])

    def label(ax, text, at, **kw):
        ax.text(
            at[0],
            at[1],
            text,
            ha="center",
            va="center",
            zorder=6,
            **kw,
            bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.75),
        )

    fig, axes = plt.subplots(1, 2, figsize=(15, 7.4))
    fig.subplots_adjust(left=0.05, right=0.9, top=0.83, bottom=0.1, wspace=0.16)
    for ax, (title, pairs, under, over) in zip(axes, PRESSURE_PANELS):
        drawn = []
        for bone in under:  # the bones pressed on: filled silhouettes, the cartilage meeting the samples on top
            b = BONES.index(bone)
            v, _ = model.bone_mesh(bone)
            w = _world(poses, b, v)
            keep = w[:, 1] < draw.DISTAL_CROP_MM if bone in ("radius", "ulna") else np.ones(len(w), bool)
            _silhouette(ax, xz(w[keep]), _BONE_FILL, filled=True, zorder=0)
            drawn.append((bone, xz(w[keep])))
            met = [frame.samples[p] for p in pairs if PAIR_BONES[PAIRS.index(p)][1] == b]
            if met:  # cartilage vertices within 3 mm of the samples that meet this bone (neutral pose, RCS)
                near, _ = cKDTree(np.concatenate([model.sample_points[s] for s in met])).query(
                    v, distance_upper_bound=3.0
                )
                cart = keep & (model.bone_thickness(bone) > 0) & np.isfinite(near)
                if cart.sum() > 3:
                    _silhouette(ax, xz(w[cart]), _CARTILAGE_FILL, filled=True, zorder=0.5)
        centre = np.concatenate([p for _, p in drawn]).mean(axis=0)
        for bone, p2 in drawn:
            _silhouette(ax, p2, "#a39d92", linewidths=0.8, zorder=0.6)
            if bone not in over:  # name it near its outer edge, clear of the bones pressing
                z = p2[:, 0].min() + 3.5 if p2[:, 0].mean() < centre[0] else p2[:, 0].max() - 3.5
                label(ax, bone, (z, np.median(p2[:, 1])), fontsize=10, color="#6b655b", style="italic")
        for bone in over:  # the bones pressing: dashed outlines
            v, _ = model.bone_mesh(bone)
            w = _world(poses, BONES.index(bone), v)
            _silhouette(ax, xz(w), _OUTLINE, linewidths=1.3, linestyles="--", zorder=3)
            label(ax, bone, xz(w).mean(axis=0), fontsize=11, color="#222222")
        lines = []
        for pair in pairs:
            k = PAIRS.index(pair)
            s = frame.samples[pair]
            w = xz(_world(poses, PAIR_BONES[k][0], model.sample_points[s]))
            p = pressure[s]
            on = p > 0
            ax.scatter(w[~on, 0], w[~on, 1], s=10, facecolors="none", edgecolors="#9a9a9a", linewidths=0.5, zorder=2)
            order = np.argsort(p[on])
            ax.scatter(
                w[on][order, 0],
                w[on][order, 1],
                s=42,
                c=p[on][order],
                cmap=cmap,
                norm=norm,
                edgecolors="k",
                linewidths=0.35,
                zorder=4,
            )
            c = frame.contact[k]
            lines.append(f"{pair}: mean {_mpa(c[0])}, peak {_mpa(c[1])}, {c[2]:.0f} mm², {c[3]:.2g} N")
        ax.set_title(title + "\n" + "\n".join(lines), fontsize=10)
        ax.set_aspect("equal")
        ax.invert_yaxis()  # volar (+x) down
        ax.set_xlabel("RCS z (mm), radial →")
        ax.set_ylabel("RCS x (mm), volar ↓")
        for text, xy, ha, va, rot in (
            ("radial", (0.985, 0.5), "right", "center", 90),
            ("ulnar", (0.015, 0.5), "left", "center", 90),
            ("volar", (0.5, 0.015), "center", "bottom", 0),
            ("dorsal", (0.5, 0.985), "center", "top", 0),
        ):
            ax.text(
                *xy,
                text,
                transform=ax.transAxes,
                fontsize=12,
                fontweight="bold",
                color="#1f3b73",
                ha=ha,
                va=va,
                rotation=rot,
                zorder=7,
                bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8),
            )
    cax = fig.add_axes([0.915, 0.17, 0.014, 0.6])
    fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), cax=cax, label="contact pressure (MPa)")
    handles = [
        plt.Line2D([], [], marker="o", lw=0, ms=9, mfc=cmap(0.6), mec="k", label="contact sample (pressure)"),
        plt.Line2D([], [], marker="o", lw=0, mfc="none", mec="#9a9a9a", label="sample out of contact"),
        plt.Line2D([], [], lw=1.3, ls="--", color=_OUTLINE, label="outline of the bone pressing"),
        matplotlib.patches.Patch(color=_BONE_FILL, label="bone pressed on"),
        matplotlib.patches.Patch(color=_CARTILAGE_FILL, label="its articular cartilage"),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=5, frameon=False)
    rs = frame.contact[PAIRS.index("radioscaphoid")]
    fig.suptitle(
        f"{name}, population design: contact pressure at the neutral pose, viewed from distal "
        f"(radioscaphoid mean {_mpa(rs[0])}, peak {_mpa(rs[1])})\n{how}",
        fontsize=12,
    )
    return draw.save(fig, out)


KINEMATIC_ANGLES = (
    "Flex/Ext: flexion (+) about z",
    "UlnD/RadD: ulnar deviation (+) about x'",
    "Pro/Sup: pronation (+) about y'' (long axis)",
)


def kinematics_figure(name: str, angle_deg: np.ndarray, runs: Sequence[RowKinematics], out: Path | None = None) -> Path:
    """Draw the scaphoid and lunate rotations against the capitate angle over the idealized ±40° sweep.

    The rotations are Cardan Z-X-Y angles; one line style per run.

    Parameters
    ----------
    name : str
        The participant, for the title and the default file name.
    angle_deg : ndarray, shape (n_frames,)
        The capitate's angle per frame, deg.
    runs : sequence of RowKinematics
        The runs drawn (`cli.run.figure_data.row_kinematics`: the population design, and for built-in
        participants also the hidden truth), each with angles of shape (n_frames, n_bodies, 3), deg, or
        None when it failed.
    out : Path, optional
        The PNG's path (default ``FIGURES / "kinematics_<name>.png"``).

    Returns
    -------
    Path
        The PNG's path.
    """

    out = out or draw.FIGURES / f"kinematics_{name}.png"
    colours = {"scaphoid": "#1f77b4", "lunate": "#d62728"}
    fig = plt.figure(figsize=(13, 6.6))
    gs = fig.add_gridspec(
        2, 2, width_ratios=(1.5, 1), left=0.07, right=0.98, top=0.88, bottom=0.1, hspace=0.35, wspace=0.22
    )
    main = fig.add_subplot(gs[:, 0])
    small = [fig.add_subplot(gs[0, 1]), fig.add_subplot(gs[1, 1])]
    lim = float(np.abs(angle_deg).max())
    main.plot([-lim, lim], [-lim, lim], color="0.6", lw=1, ls=":", label="identity (moves with the capitate)")
    notes, ends = [], []
    for run in runs:
        label, style, angles = run.label, run.style, run.angles_deg
        if angles is None:
            notes.append(f"{label}: {run.message}")
            continue
        for bone in ("scaphoid", "lunate"):
            a = angles[:, BONES.index(bone)]
            kw = dict(color=colours[bone], ls=style, marker="o", ms=3.5)
            main.plot(angle_deg, a[:, 0], label=f"{bone}, {label}", **kw)
            ends.append(
                f"{bone[:8]:<8} {label:<12} {a[0, 0]:+6.1f}° at {angle_deg[0]:+.0f}°, "
                f"{a[-1, 0]:+6.1f}° at {angle_deg[-1]:+.0f}°"
            )
            for ax, k in zip(small, (1, 2)):
                ax.plot(angle_deg, a[:, k], **kw)
    main.axhline(0, color="0.85", lw=0.8, zorder=0)
    main.axvline(0, color="0.85", lw=0.8, zorder=0)
    main.set_xlabel("capitate angle (deg): extension −  /  flexion +")
    main.set_ylabel("bone flexion (+) / extension (−), deg")
    main.set_title("flexion–extension about the RCS z axis")
    main.set_xlim(-lim - 3, lim + 3)
    main.set_ylim(-lim - 3, lim + 3)
    main.set_aspect("equal")
    main.legend(loc="upper left", fontsize=9)
    if ends:
        draw.note_box(main, ends, 0.03, "bottom", family="monospace")
    for ax, k in zip(small, (1, 2)):
        ax.set_title(KINEMATIC_ANGLES[k], fontsize=10)
        ax.set_ylabel("deg")
        ax.axhline(0, color="0.85", lw=0.8, zorder=0)
        ax.set_xlim(-lim - 3, lim + 3)
    small[1].set_xlabel("capitate angle (deg)")
    fig.suptitle(
        f"{name}: carpal kinematics over the idealized flexion–extension sweep "
        f"(Cardan Z-X-Y angles, RCS, neutral = 0)" + ("\n" + "; ".join(notes) if notes else ""),
        fontsize=12,
    )
    return draw.save(fig, out)
