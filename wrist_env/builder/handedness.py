"""Is a participant's wrist the side the template is (a right one)? Each bone against the template's, as
given and mirrored.

A folder's `side` says which hand its meshes are; a left one is mirrored to a right one on loading
(`participants.folder`). Declared wrongly, the bones reach the build as a left wrist in the radius
coordinate system (RCS): a reflection through the plane of the long axis and the radioulnar direction,
z → −z. Carpal bones and the distal radius are chiral, so a similarity transform (rotation, scale,
shift) fits the template's bone much closer to the participant's than its mirror image does, or the
reverse: on the built-in P1–P3 (1,500 vertices a bone) the template fits 0.13–0.77 mm as is and
0.87–3.66 mm mirrored, and the other way round once their meshes are mirrored. A build whose bones the
mirrored template fits better in most bones stops before the morph (~1 min) with the side named (the
check takes ~0.5 s); the joint spaces after the cartilage step (`pipeline.JOINT_SPACE_MM`) stay a
later check of how the bones sit.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from wrist_env.errors import BuildError

SAMPLES = 1500
"""Vertices drawn from each mesh for the fit (the misfit's mean needs no more)."""
ITERATIONS = 30
"""Iterations of the closest-point similarity fit (ICP with scale, Umeyama's closed form each)."""
MIRROR = np.array([1.0, 1.0, -1.0])
"""The reflection a wrong `side` leaves in the RCS: z → −z."""


def _sample(vertices: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    v = np.asarray(vertices, dtype=np.float64)
    return v if len(v) <= SAMPLES else v[np.sort(rng.choice(len(v), SAMPLES, replace=False))]


def similarity_misfit(source: np.ndarray, target: np.ndarray) -> float:
    """Mean closest-vertex distance (mm, both ways) after fitting `source` (n, 3) to `target` (m, 3) by
    a similarity transform (no reflection), by ICP from their centroids laid on each other."""
    source, target = np.array(source, dtype=np.float64), np.array(target, dtype=np.float64)
    tree = cKDTree(target)
    x = source - source.mean(axis=0) + target.mean(axis=0)
    for _ in range(ITERATIONS):
        _, nearest = tree.query(x)
        y = target[nearest]
        mx, my = x.mean(axis=0), y.mean(axis=0)
        U, S, Vt = np.linalg.svd((x - mx).T @ (y - my))
        d = np.array([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))])
        rotation = Vt.T @ (d[:, None] * U.T)
        scale = (S * d).sum() / ((x - mx) ** 2).sum()
        x = scale * (x - mx) @ rotation.T + my
    there, _ = tree.query(x)
    back, _ = cKDTree(x).query(target)
    return float(0.5 * (there.mean() + back.mean()))


def side_misfits(template: dict, bones: dict, seed: int = 0) -> dict[str, tuple[float, float]]:
    """Per bone both have: (misfit of the template's bone as is, of its mirror image) in mm, each bone's
    vertices (RCS, mm) from `template` and `bones` (name → anything with `.vertices`)."""
    rng = np.random.default_rng(seed)
    out = {}
    for name in (b for b in template if b in bones):
        source, target = _sample(template[name].vertices, rng), _sample(bones[name].vertices, rng)
        out[name] = (similarity_misfit(source, target), similarity_misfit(source * MIRROR, target))
    return out


def check_side(participant: str, template: dict, bones: dict, seed: int = 0) -> dict[str, tuple[float, float]]:
    """`side_misfits`, or BuildError naming them if the mirrored template fits more bones better than the
    template as is (the bones are the other hand's)."""
    misfits = side_misfits(template, bones, seed)
    mirrored = [b for b, (as_is, mirror) in misfits.items() if mirror < as_is]
    if 2 * len(mirrored) > len(misfits):
        listed = "; ".join(
            f"{b} {as_is:.2f} mm as is, {mirror:.2f} mm mirrored" for b, (as_is, mirror) in misfits.items()
        )
        raise BuildError(
            f"participant {participant!r}: the bones are the other hand's: the template's bones (a right wrist) "
            f"fit {len(mirrored)} of {len(misfits)} closer mirrored ({listed}). Check `side` in "
            f'participant.toml (right-hand meshes declared "left" are mirrored, and the reverse).'
        )
    return misfits
