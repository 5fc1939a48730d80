"""An animated idealized sweep (GIF): bones, ligament fibres coloured by force, radiocarpal pressure.

Pictures take data: a `SweepFrames` holds the simulated sweep (`cli.run.figure_data.sweep_frames` simulates
it); nothing here loads a participant or runs the solver."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.colors import to_rgb

from wrist_env.figures import draw
from wrist_env.model import BONES, PAIR_BONES, PAIRS, Model

_LIGHT = np.array([0.3, 0.5, 1.0]) / np.linalg.norm([0.3, 0.5, 1.0])  # from the radial side, above
RADIOCARPAL = ("radioscaphoid", "radiolunate")


@dataclass(frozen=True)
class SweepFrames:
    """The population design's idealized sweep of a participant's model, as the animation draws it.

    name: the participant; angle_deg (n_frames,): the capitate's angle (deg, flexion +); poses (n_frames,
    n_bodies, 4, 4): each body's pose (RCS, mm); bundle_force (n_frames, n_bundles): each ligament
    bundle's force (N); pressure_mpa (n_frames, n_radiocarpal): the pressure (MPa) of the `RADIOCARPAL`
    pairs' samples, in `model.sample_points` order, pair after pair; samples: those pairs' slices of
    `model.sample_points`."""

    name: str
    angle_deg: np.ndarray
    poses: np.ndarray
    bundle_force: np.ndarray
    pressure_mpa: np.ndarray
    samples: tuple[slice, ...]


def _bone_surfaces(model: Model) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per bone: its neutral vertices (mm), the faces drawn (radius and ulna cropped) and its RGB colour."""
    surfaces = []
    for b, bone in enumerate(BONES):
        v = model.vertices[model.vertex_offsets[b] : model.vertex_offsets[b + 1]]
        f = model.faces[model.face_offsets[b] : model.face_offsets[b + 1]]
        if bone in ("radius", "ulna"):
            f = draw.crop(v, f, draw.DISTAL_CROP_MM)
        surfaces.append((v, f, np.array(to_rgb(draw.BONE_COLOUR[bone]))))
    return surfaces


def _bone_polygons(surfaces: list, poses_frame: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of every bone at one frame seen from the radial side: (n, 3, 2) in (volar x, proximal y)
    mm, painter-sorted (far first), and their shaded colours (n, 4)."""
    tris, colours, depth = [], [], []
    for b, (v, f, base) in enumerate(surfaces):
        t = (v @ poses_frame[b, :3, :3].T + poses_frame[b, :3, 3])[f]
        normal = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
        normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
        shade = 0.45 + 0.55 * np.clip(normal @ _LIGHT, 0.0, 1.0)
        tris.append(t[:, :, :2])
        colours.append(np.column_stack([shade[:, None] * base, np.ones(len(t))]))
        depth.append(t[:, :, 2].mean(axis=1))
    order = np.argsort(np.concatenate(depth))  # radial view: +z towards the viewer, far (ulnar) first
    return np.concatenate(tris)[order], np.concatenate(colours)[order]


def animation_figure(model: Model, sweep: SweepFrames, out: Path | None = None, *, fps: float = 4.0) -> Path:
    """Write a GIF of `sweep`, the population design's idealized sweep of `model` (radial view).

    Parameters
    ----------
    model : Model
        The participant's model (its bone meshes and contact samples).
    sweep : SweepFrames
        The sweep simulated: poses of shape (n_frames, n_bodies, 4, 4), mm; bundle forces, N; radiocarpal
        pressures, MPa.
    out : Path, optional
        The GIF's path (default ``FIGURES / "animation_<name>.gif"``; its folder is made if missing).
    fps : float, default 4.0
        Frames per second of the GIF.

    Returns
    -------
    Path
        The GIF's path.
    """
    name, n_frames = sweep.name, len(sweep.angle_deg)
    out = Path(out) if out else draw.FIGURES / f"animation_{name}.gif"
    out.parent.mkdir(parents=True, exist_ok=True)
    slices = list(sweep.samples)
    radiocarpal = np.r_[tuple(slices)]
    samples = model.sample_points[radiocarpal]
    # the bone each sample lies on: its pair's sample body
    sample_body = np.repeat([PAIR_BONES[PAIRS.index(p)][0] for p in RADIOCARPAL], [s.stop - s.start for s in slices])
    pressures = list(sweep.pressure_mpa)
    p_max = max(float(np.percentile(p[p > 0], 99)) if (p > 0).any() else 1.0 for p in pressures)
    f_max = max(float(np.nanmax(sweep.bundle_force)), 1.0)
    force_map, pressure_cmap = plt.get_cmap("viridis"), plt.get_cmap("inferno")
    surfaces = _bone_surfaces(model)

    fig, ax = plt.subplots(figsize=(6.4, 6.4), constrained_layout=True)
    ax.set_aspect("equal")
    ax.set_xlim(-25, 25)
    ax.set_ylim(-38, 14)
    ax.set_xlabel("dorsal  ←  x (mm)  →  volar")
    ax.set_ylabel("distal  ←  y (mm)  →  proximal")
    bones = PolyCollection([], linewidths=0.3, edgecolors="face")  # edges in the face colour: no seams
    fibres = LineCollection([], linewidths=1.6, cmap=force_map, norm=plt.Normalize(0, f_max))
    contact = ax.scatter([], [], s=6, c=[], cmap=pressure_cmap, vmin=0, vmax=p_max, zorder=4)
    ax.add_collection(bones)
    ax.add_collection(fibres)
    fibres.set_zorder(3)
    fig.colorbar(fibres, ax=ax, shrink=0.6, label="ligament fibre force: its bundle's (N)")
    fig.colorbar(contact, ax=ax, shrink=0.6, label="radiocarpal contact pressure (MPa)")
    title = ax.set_title("")

    def show(f: int):
        poses = sweep.poses[f]
        polygons, colours = _bone_polygons(surfaces, poses)
        bones.set_verts(polygons)
        bones.set_facecolor(colours)
        a = np.einsum("nij,nj->ni", poses[model.fibre_bones[:, 0], :3, :3], model.fibre_origin)
        a += poses[model.fibre_bones[:, 0], :3, 3]
        b = np.einsum("nij,nj->ni", poses[model.fibre_bones[:, 1], :3, :3], model.fibre_insertion)
        b += poses[model.fibre_bones[:, 1], :3, 3]
        fibres.set_segments(np.stack([a[:, :2], b[:, :2]], axis=1))
        fibres.set_array(sweep.bundle_force[f][model.fibre_ligament])
        world = np.einsum("nij,nj->ni", poses[sample_body, :3, :3], samples) + poses[sample_body, :3, 3]
        on = pressures[f] > 0
        contact.set_offsets(world[on, :2])
        contact.set_array(pressures[f][on])
        angle = sweep.angle_deg[f]
        title.set_text(
            f"{name}, population design, radial view\ncapitate {abs(angle):.0f}° "
            f"{'flexion' if angle >= 0 else 'extension'} (frame {f + 1}/{n_frames})"
        )
        return bones, fibres, contact, title

    FuncAnimation(fig, show, frames=n_frames, blit=False).save(out, writer=PillowWriter(fps=fps), dpi=90)
    plt.close(fig)
    return out
