"""Where the axial load goes at neutral (issue 10: the radiocarpal load share).

For each participant (population design, capitate held at neutral under the validation's 100 N):
the contact force on each bone of each contact pair's sample body (the distal row's parts, the
triquetrum with the lunate) and the neutral gaps of those samples to the opposing surface, to see
why the STT and triquetrohamate joints carry little. Run: `python experiments/load_paths.py P1`.
"""

from __future__ import annotations

import sys

import numpy as np
from scipy.spatial import cKDTree

from wrist_env import design
from wrist_env.model import BODY_PARTS, BONES, PAIR_BONES, PAIRS
from wrist_env.participants.registry import load_model
from wrist_env.solver import simulate as sim
from wrist_env.solver.contact import OUTSIDE_MM, sdf_lookup
from wrist_env.solver.outputs import pressure_map
from wrist_env.validation import NEUTRAL_LOAD_N


def signed_distance(model, b: int, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed distance (mm, NaN off the grid) and its gradient (n, 3) of body b's contact grid (cartilage
    folded in) at neutral-pose points (n, 3): the solver's own trilinear look-up."""
    shape, origin, h = model.grid_shape[b], model.grid_origin[b], float(model.grid_spacing[b])
    values = np.ascontiguousarray(model.grid_values, dtype=np.float32)
    offset = int(model.grid_offsets[b])
    d, grad = np.empty(len(points)), np.empty((len(points), 3))
    for i, q in enumerate(np.asarray(points, dtype=np.float64)):
        d[i], grad[i] = sdf_lookup(values, offset, shape, origin, h, q)
    d[d >= OUTSIDE_MM] = np.nan
    return d, grad


def sample_parts(model, k: int) -> tuple[np.ndarray, slice]:
    """The part (index into `BODY_PARTS` of the pair's sample body) of each sample of pair k, and the pair's slice."""
    body = PAIR_BONES[k][0]
    s = slice(model.sample_offsets[k], model.sample_offsets[k + 1])
    vertices = model.vertices[model.vertex_offsets[body] : model.vertex_offsets[body + 1]]
    part = model.vertex_part[model.vertex_offsets[body] : model.vertex_offsets[body + 1]]
    return part[cKDTree(vertices).query(model.sample_points[s])[1]], s


def load_paths(name: str) -> list[dict]:
    """Per pair and sample-body part: contact force (N, magnitude), sample area (mm²), neutral gap (mm)."""
    model = load_model(name)
    result = sim.simulate(model, design.population(), sim.loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N))
    poses = result.poses[0]
    pressure = pressure_map(model, poses)
    rows = []
    for k, pair in enumerate(PAIRS):
        body, grid_body = PAIR_BONES[k]
        owner, s = sample_parts(model, k)
        force = (pressure[s] * model.sample_area[s])[:, None] * (model.sample_normals[s] @ poses[body, :3, :3].T)
        gap = signed_distance(model, grid_body, model.sample_points[s])[0]
        for q, part_name in enumerate(BODY_PARTS[BONES[body]]):
            mine = owner == q
            if mine.any():
                rows.append(
                    {
                        "pair": pair,
                        "part": part_name,
                        "force_n": float(np.linalg.norm(force[mine].sum(0))),
                        "area_mm2": float(model.sample_area[s][mine].sum()),
                        "gap_min_mm": float(np.nanmin(gap[mine])),
                        "gap_median_mm": float(np.nanmedian(gap[mine])),
                    }
                )
    rs, rl = PAIRS.index("radioscaphoid"), PAIRS.index("radiolunate")
    rows.append(
        {
            "pair": "RS/RL force ratio",
            "part": "",
            "force_n": float(result.contact[0, rs, 3] / result.contact[0, rl, 3]),
            "area_mm2": np.nan,
            "gap_min_mm": np.nan,
            "gap_median_mm": np.nan,
        }
    )
    return rows


def main(names) -> None:
    for name in names:
        print(f"{name}, population design, neutral, {NEUTRAL_LOAD_N:g} N")
        print("| pair | part | force (N) | sample area (mm²) | neutral gap min / median (mm) |\n|---|---|---|---|---|")
        for r in load_paths(name):
            print(
                f"| {r['pair']} | {r['part']} | {r['force_n']:.2f} | {r['area_mm2']:.0f} | "
                f"{r['gap_min_mm']:.2f} / {r['gap_median_mm']:.2f} |"
            )


if __name__ == "__main__":
    main(sys.argv[1:] or ["P1"])
