"""Write the built-in participants P1–P3 (deterministic): Table 1 facts, warp, hidden truth.

The participants are synthetic and say so: each is the anatomy template under
a smooth participant-specific warp and an isotropic scale (women smaller than
the template, the man larger), with ground-truth ligament properties drawn
from Table 2's normal distributions truncated at ±3 SD (fixed seeds), all
ligaments intact. Run: `python experiments/authoring/make_participants.py`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from wrist_env import design, ligaments, table2
from wrist_env.builder.warp import random_warp

OUT = Path(__file__).resolve().parents[2] / "wrist_env" / "participants" / "data"

# Preprint Table 1 (all right wrists).
TABLE_1 = {
    "P1": dict(sex="female", age=39, facet_type="I", task="radial-ulnar deviation", scale=0.95, seed=101),
    "P2": dict(sex="male", age=38, facet_type="I", task="grip", scale=1.06, seed=202),
    "P3": dict(sex="female", age=29, facet_type="II", task="flexion-extension", scale=0.92, seed=303),
}


def main() -> None:
    for name, row in TABLE_1.items():
        warp = random_warp(row["seed"], amplitude_mm=0.8, width_mm=15.0, n_centres=6, extent_mm=25.0)
        warp = type(warp).from_dict({**warp.as_dict(), "scale": row["scale"]})
        truth_seed = row["seed"] + 1
        materials = table2.sample_materials(1, truth_seed)[0]
        action = np.concatenate([materials, np.ones(len(ligaments.INJURABLE))])
        truth = design.from_action(action)
        folder = OUT / name
        folder.mkdir(parents=True, exist_ok=True)
        info = {k: row[k] for k in ("sex", "age", "facet_type", "task")}
        info.update(name=name, warp=warp.as_dict(), truth_seed=truth_seed)
        (folder / "participant.json").write_text(json.dumps(info, indent=2) + "\n")
        (folder / "truth.json").write_text(json.dumps(truth.as_dict(), indent=2) + "\n")
        print(f"{name}: scale {row['scale']}, truth z-scores {np.round(table2.z_scores(truth), 2).tolist()}")


if __name__ == "__main__":
    main()
