"""Figures of the model's geometry: bones, cartilage, ligaments (model) and the template's annotations.

Pictures take data: a `Model` and the template's bone surfaces and annotations, loaded by the command
(`cli.run.figure_data`); nothing here loads a participant or builds the template."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

from wrist_env.figures import draw
from wrist_env.ligaments import ALL_LIGAMENT_NAMES
from wrist_env.model import BONES, PAIRS, Model

MODEL_PANELS = (("volar view", 0, 0), ("radial view", 0, 90), ("dorsal view", 0, 180))


def _display_faces(bone: str, vertices, faces, thickness):
    """Faces worth drawing: cropped to the wrist, without the radius solid's walls and base."""
    faces = draw.crop(vertices, faces, draw.DISTAL_CROP_MM)
    if bone == "radius":
        v = vertices[faces]
        n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
        n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-12
        articular = thickness[faces].min(axis=1) > 0
        faces = faces[articular | (np.abs(n[:, 1]) < 0.9) & (v[:, :, 1].min(axis=1) > 2.0)]
    return faces


def model_figure(model: Model, name: str, out: Path | None = None) -> Path:
    """Draw the bones, cartilage coloured by thickness, ligament fibres and the RSC membrane of a model.

    Parameters
    ----------
    model : Model
        Participant `name`'s model (meshes in mm, cartilage thickness in mm).
    name : str
        The participant, for the title and the default file name.
    out : Path, optional
        The PNG's path (default ``FIGURES / "model_<name>.png"``).

    Returns
    -------
    Path
        The PNG's path.
    """

    out = out or draw.FIGURES / f"model_{name}.png"
    norm = matplotlib.colors.Normalize(0.0, 1.1)
    cmap = plt.get_cmap("viridis")
    tris, colours = [], []
    for bone in BONES:
        v, f = model.bone_mesh(bone)
        t = model.bone_thickness(bone)
        f = _display_faces(bone, v, f, t)
        ft = t[f].mean(axis=1)
        c = np.array([matplotlib.colors.to_rgba(draw.BONE_COLOUR[bone])] * len(f))
        covered = t[f].min(axis=1) > 0
        c[covered] = cmap(norm(ft[covered]))
        tris.append(v[f])
        colours.append(c)
    tris, colours = np.concatenate(tris), np.concatenate(colours)
    fibres = np.stack([model.fibre_origin, model.fibre_insertion], axis=1)
    fibre_colours = [draw.LIGAMENT_COLOURS[ALL_LIGAMENT_NAMES[i]] for i in model.fibre_ligament]
    nodes = model.membrane_nodes
    membrane = np.stack([nodes[model.membrane_connectors[:, 0]], nodes[model.membrane_connectors[:, 1]]], axis=1)
    fig = plt.figure(figsize=(17, 6.5))
    fig.subplots_adjust(left=0.0, right=0.93, wspace=0.0, top=0.93, bottom=0.08)
    for k, (title, elev, azim) in enumerate(MODEL_PANELS):
        ax = fig.add_subplot(1, 3, k + 1, projection="3d", computed_zorder=False)
        ax.add_collection3d(
            Poly3DCollection(
                draw.to_plot(tris),
                facecolors=colours,
                linewidths=0,
                shade=True,
                lightsource=matplotlib.colors.LightSource(45, 45),
                zorder=1,
            )
        )
        ax.add_collection3d(Line3DCollection(draw.to_plot(fibres), colors=fibre_colours, linewidths=2.0, zorder=3))
        ax.add_collection3d(
            Line3DCollection(draw.to_plot(membrane), colors=draw.LIGAMENT_COLOURS["RSC"], linewidths=1.0, zorder=3)
        )
        ax.view_init(elev=elev, azim=azim - 90)
        draw.frame_axes(ax, tris.reshape(-1, 3), title)
    handles = [
        plt.Line2D([], [], color=draw.LIGAMENT_COLOURS[n], lw=2, label=n + (" (membrane)" if n == "RSC" else ""))
        for n in ALL_LIGAMENT_NAMES
    ]
    fig.legend(handles=handles, loc="lower center", ncol=13, frameon=False)
    sm = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=fig.axes, shrink=0.45, label="cartilage thickness (mm)", location="right")
    fig.suptitle(
        f"{name}: bones, cartilage coloured by thickness, ligament fibres (drawn on top) "
        "and the RSC membrane; RCS, neutral pose"
    )
    return draw.save(fig, out)


ANNOTATION_PANELS = (
    # title, bones shown, elevation, azimuth (plot frame: x radial, y dorsal-negative, z proximal)
    ("carpus, volar view", ("scaphoid", "lunate", "capitate", "trapezium"), 0, 0),
    ("carpus, dorsal view", ("scaphoid", "lunate", "capitate", "trapezium"), 0, 180),
    ("carpus, proximal view", ("scaphoid", "lunate", "capitate", "trapezium"), 90, 0),
    ("radius and ulna, distal view", ("radius", "ulna"), -90, 0),
)


PAIR_COLOURS = dict(
    zip(
        PAIRS,
        ("#f4a6a0", "#9fc3e0", "#b9e3ae", "#d3bde0", "#fdd49e", "#a6dcd0", "#e0c39f", "#c9c9f2")
        + ("#f2c6de", "#c7e9b4", "#fbb4ae", "#b3cde3"),
        strict=False,
    )
)
"""One colour per contact pair's cartilage (`model.PAIRS`) in the annotations figure."""


def annotations_figure(bones: dict, annotations, out: Path | None = None) -> Path:
    """Draw the template with its cartilage coverage and ligament attachment sites, for review.

    Parameters
    ----------
    bones : dict of str to BoneSurface
        Bone name -> its surface (`anatomy.template.BoneSurface`: vertices of shape (n, 3), mm; faces of
        shape (m, 3); the radius's `solid` vertex indices).
    annotations : Annotations
        The template's (`anatomy.annotations.Annotations`: `coverage`, articulation -> (bone a, bone b,
        vertex mask of a, of b); `sites`, ligament -> sites with `bone` and vertex `mask`).
    out : Path, optional
        The PNG's path (default ``FIGURES / "template_annotations.png"``).

    Returns
    -------
    Path
        The PNG's path.
    """

    ann = annotations
    out = out or draw.FIGURES / "template_annotations.png"
    art_colours = PAIR_COLOURS
    fig = plt.figure(figsize=(18, 5.6))
    for k, (title, shown, elev, azim) in enumerate(ANNOTATION_PANELS):
        ax = fig.add_subplot(1, 4, k + 1, projection="3d")
        for name in shown:
            bone = bones[name]
            f = draw.crop(bone.vertices, bone.faces, 14.0)
            if name == "radius":  # the articular solid's walls and base hide the fossae
                f = f[(bone.vertices[f][:, :, 1] < bone.vertices[bone.solid, 1].max() - 0.1).all(axis=1)]
            colours = np.array([matplotlib.colors.to_rgba(draw.BONE_COLOUR[name])] * len(f))
            for art, (a, b, ma, mb) in ann.coverage.items():
                for bn, m in ((a, ma), (b, mb)):
                    if bn == name:
                        colours[m[f].all(axis=1)] = matplotlib.colors.to_rgba(art_colours[art], 0.9)
            draw.add_mesh(ax, bone.vertices, f, None, facecolors=colours)
            for lig, sites in ann.sites.items():
                for s in sites:
                    if s.bone == name:
                        p = draw.to_plot(bone.vertices[s.mask])
                        ax.scatter(p[:, 0], p[:, 1], p[:, 2], s=9, color=draw.LIGAMENT_COLOURS[lig], depthshade=False)
        ax.view_init(elev=elev, azim=azim - 90)
        draw.frame_axes(ax, np.vstack([bones[b].vertices[bones[b].vertices[:, 1] < 14.0] for b in shown]), title)
    handles = [plt.Line2D([], [], color=c, lw=6, label=a) for a, c in art_colours.items()]
    handles += [
        plt.Line2D([], [], color=draw.LIGAMENT_COLOURS[n], marker="o", lw=0, label=n) for n in ALL_LIGAMENT_NAMES
    ]
    fig.legend(handles=handles, loc="lower center", ncol=8, frameon=False)
    fig.suptitle("Template annotations: cartilage coverage per articulation (patches) and ligament sites (dots), RCS")
    return draw.save(fig, out)
