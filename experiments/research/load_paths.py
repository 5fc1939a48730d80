"""Where the axial load goes at neutral (issues 10 and 33: the load path).

For each participant (population design, capitate held at neutral under the validation's 100 N):
the contact force on each bone of each contact pair's sample body (the distal row's parts, the
triquetrum with the lunate) with the neutral gaps of those samples to the opposing surface, then
the force and share of each articulation (`model.ARTICULATIONS`: the midcarpal shares against
Viegas 1993, the ulnar share against Palmer & Werner 1984) as `wrist-bench validate` checks them,
and the space a TFCC would fill (`ulnocarpal_space`).
Run: `python experiments/research/load_paths.py P1 [P2 ...] [--load-direction erhart2020]` (the load along the
radius by default, or the tendon rig's resultant: `settings.LOAD_DIRECTIONS`).
"""

from __future__ import annotations

import argparse

import numpy as np

from wrist_env import design
from wrist_env.model import BODY_PARTS, BONES, PAIR_BONES, PAIRS
from wrist_env.participants.registry import load_model
from wrist_env.solver import drivers
from wrist_env.solver import simulate as sim
from wrist_env.solver.contact import OUTSIDE_MM, sdf_lookup
from wrist_env.solver.outputs import articulation_forces, pair_slice, pressure_map, sample_parts
from wrist_env.solver.settings import DEFAULT_LOADS, LOAD_DIRECTIONS
from wrist_env.validation import NEUTRAL_LOAD_N, load_shares_pct


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


def part_gaps(name: str, model, poses) -> list[dict]:
    """Per pair and sample-body part: contact force (N, pressure × area), sample area (mm²), neutral gap (mm)."""
    load = pressure_map(model, poses) * model.sample_area
    rows = []
    for k, pair in enumerate(PAIRS):
        body, grid_body = PAIR_BONES[k]
        owner, s = sample_parts(model, pair), pair_slice(model, pair)
        gap = signed_distance(model, grid_body, model.sample_points[s])[0]
        for q, part_name in enumerate(BODY_PARTS[BONES[body]]):
            mine = owner == q
            if mine.any():
                rows.append(
                    {
                        "pair": pair,
                        "part": part_name,
                        "force_n": float(load[s][mine].sum()),
                        "area_mm2": float(model.sample_area[s][mine].sum()),
                        "gap_min_mm": float(np.nanmin(gap[mine])),
                        "gap_median_mm": float(np.nanmedian(gap[mine])),
                    }
                )
    return rows


HEAD_WIDTH_MM = 8.0  # the ulnar head beside the sigmoid notch: up to this far ulnar of the radius' ulnar corner


def ulnocarpal_space(model) -> dict:
    """Where a TFCC would sit, at neutral: the closest approach (mm) of the lunate and of the triquetrum
    to the ulna's surface, and the ulnar variance (mm, + ulna plus): the radius' ulnar corner (its most
    ulnar vertex within 6 mm of the RCS origin along y) minus the most distal point of the ulnar head
    (ulna vertices up to `HEAD_WIDTH_MM` ulnar of that corner, which leaves out the styloid), along y."""
    import trimesh

    def body(b):
        lo, hi = model.vertex_offsets[b], model.vertex_offsets[b + 1]
        faces = model.faces[model.face_offsets[b] : model.face_offsets[b + 1]]
        return model.vertices[lo:hi], faces, model.vertex_part[lo:hi]

    radius_v, _, _ = body(BONES.index("radius"))
    ulna_v, ulna_f, _ = body(BONES.index("ulna"))
    lunate_v, _, part = body(BONES.index("lunate"))
    _, distance, _ = trimesh.proximity.closest_point(trimesh.Trimesh(ulna_v, ulna_f, process=False), lunate_v)
    rim = radius_v[radius_v[:, 1] < 6.0]
    corner = rim[np.argmin(rim[:, 2])]
    head = ulna_v[(ulna_v[:, 2] <= corner[2]) & (ulna_v[:, 2] >= corner[2] - HEAD_WIDTH_MM)]
    out = {f"{p}_to_ulna_mm": float(distance[part == q].min()) for q, p in enumerate(BODY_PARTS["lunate"])}
    return out | {"ulnar_variance_mm": float(corner[1] - head[:, 1].min())}


def main(names, load_direction: str = DEFAULT_LOADS) -> None:
    for name in names:
        model = load_model(name)
        driver = drivers.loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N, direction=load_direction)
        result = sim.simulate(model, design.population(), driver)
        total = driver.resultant(0)
        print(
            f"{name}, population design, neutral, {NEUTRAL_LOAD_N:g} N on the {load_direction} lines, resultant {total.round(2)} N"
        )
        print("| pair | part | force (N) | sample area (mm²) | neutral gap min / median (mm) |\n|---|---|---|---|---|")
        for r in part_gaps(name, model, result.poses[0]):
            print(
                f"| {r['pair']} | {r['part']} | {r['force_n']:.2f} | {r['area_mm2']:.0f} | "
                f"{r['gap_min_mm']:.2f} / {r['gap_median_mm']:.2f} |"
            )
        forces, shares = articulation_forces(model, result.poses[0]), load_shares_pct(model, result)
        print("\n| articulation | force (N) | share (%) |\n|---|---|---|")
        for joint, force in forces.items():
            share = f"{shares[joint]:.1f}" if joint in shares else ""
            print(f"| {joint} | {force:.2f} | {share} |")
        space = ulnocarpal_space(model)
        print(
            f"\nulnocarpal space: lunate {space['lunate_to_ulna_mm']:.2f} mm and triquetrum "
            f"{space['triquetrum_to_ulna_mm']:.2f} mm from the ulna; ulnar variance {space['ulnar_variance_mm']:+.2f} mm"
        )
        rs, rl = forces["radioscaphoid"], forces["radiolunate"]
        print(
            f"\nRS/RL force ratio {rs / rl:.2f}; midcarpal shares of the four midcarpal joints, ulnocarpal of RS + RL + ulnocarpal\n"
        )


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("participants", nargs="*", default=["P1"])
    parser.add_argument("--load-direction", choices=LOAD_DIRECTIONS, default=DEFAULT_LOADS)
    args = parser.parse_args()
    main(args.participants, args.load_direction)
