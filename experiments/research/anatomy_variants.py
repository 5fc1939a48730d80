"""The numbers behind docs/validation.md's "Anatomy variants" and its validation prose.

Prints, on this machine (each model built or read from the cache):
1. for P1 (population design), one Markdown row per anatomy variant: the
   `wrist-bench validate` values and the Monte Carlo designs that fail out of
   200 (`sampler.monte_carlo_actions`, seed 7, idealized sweep);
2. the same failure count for P1–P3 with the default anatomy;
3. the share of 1,000 uniform random designs (full bounds, tears; 9-frame
   sweep; the draw of `tests/solver/test_simulate.py`) flagged as failed on P1;
4. the contact force each bone of the distal row carries at neutral under
   the validation's 100 N, P1 population design (how little reaches the STT).

Run: `python experiments/research/anatomy_variants.py` (a few minutes; two extra builds on first use).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from wrist_env import design
from wrist_env.builder.params import BuildParams
from wrist_env.model import BODY_PARTS, BONES, PAIR_BONES, PAIRS
from wrist_env.montecarlo import sampler
from wrist_env.participants.registry import load_model
from wrist_env.solver import arrays
from wrist_env.solver.drivers import idealized, loaded
from wrist_env.solver.forces import sample_pressures
from wrist_env.solver.rigid import pose_state
from wrist_env.solver.simulate import simulate, simulate_batch
from wrist_env.validation import NEUTRAL_LOAD_N, validate

VARIANTS = (
    (
        "builder 1: moulded fossae, five bones (`--fossa-sweep 0 0 --no-distal-row`)",
        BuildParams(fossa_sweep_deg=(0.0, 0.0), distal_row=False),
    ),
    ("swept fossae only (`--no-distal-row`)", BuildParams(distal_row=False)),
    ("distal row + swept fossae, no TC/TH (`--no-fixed-ligaments`)", BuildParams(fixed_ligaments=False)),
    ("**default**: distal row + swept fossae + TC/TH", BuildParams()),
)


def monte_carlo_failures(model, n: int = 200, seed: int = 7) -> int:
    actions = sampler.monte_carlo_actions(n, np.random.SeedSequence(seed))
    return sum(not r.ok for r in simulate_batch(model, [design.from_action(a) for a in actions], idealized(model)))


def variant_row(label: str, params: BuildParams) -> str:
    model = load_model("P1", params)
    report = validate("P1", model=model, params=params)
    v = {c.id: c.value for c in report.rows}

    def f(key, fmt="{:.2f}"):
        return fmt.format(v[key]) if np.isfinite(v[key]) else "run fails"

    return (
        f"| {label} | {f('scaphoid_slope')} / {f('lunate_slope')} | {f('rs_rl_force_ratio')} | "
        f"{f('sl_gap_growth_mm', '{:+.2f} mm')} | {f('rs_mean_pressure_mpa')} MPa | "
        f"{f('slil_force_30ext_n', '{:.0f}')} N | {sum(c.passed for c in report.rows)}/7 | "
        f"{monte_carlo_failures(model)} / 200 |"
    )


def distal_row_forces(model) -> dict:
    """Contact force (N) on each part of the capitate body at neutral under `NEUTRAL_LOAD_N`."""
    result = simulate(model, design.population(), loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N))
    poses = result.poses[0]
    R, x = pose_state(poses, model.com)
    pressure = np.zeros(len(model.sample_points))
    sample_pressures(R, x, model.com, arrays.grids(model), np.ascontiguousarray(model.contact_law, float), pressure)
    c = BONES.index("capitate")
    vertices = model.vertices[model.vertex_offsets[c] : model.vertex_offsets[c + 1]]
    part = model.vertex_part[model.vertex_offsets[c] : model.vertex_offsets[c + 1]]
    tree = cKDTree(vertices)
    out = {p: 0.0 for p in BODY_PARTS["capitate"]}
    for k in range(len(PAIRS)):
        if PAIR_BONES[k][0] != c:
            continue
        s = slice(model.sample_offsets[k], model.sample_offsets[k + 1])
        owner = part[tree.query(model.sample_points[s])[1]]
        for q, name in enumerate(BODY_PARTS["capitate"]):
            out[name] += float((pressure[s] * model.sample_area[s])[owner == q].sum())
    return out


def main() -> None:
    print(
        "| variant | scaphoid / lunate slope | RS / RL force (100 N) | SL gap growth, SLIL cut | RS mean pressure "
        "| SLIL at 30° ext. | checks passed | Monte Carlo designs failed |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for label, params in VARIANTS:
        print(variant_row(label, params), flush=True)
    for name in ("P1", "P2", "P3"):
        print(f"{name}: {monte_carlo_failures(load_model(name))} of 200 Monte Carlo designs failed (default anatomy)")
    p1 = load_model("P1")
    rng = np.random.default_rng(11)
    results = simulate_batch(
        p1, [design.from_action(a) for a in rng.uniform(-1, 1, (1000, 27))], idealized(p1, n_frames=9)
    )
    print(f"P1: {sum(not r.ok for r in results) / 10:.1f} % of 1,000 uniform random designs failed")
    forces = distal_row_forces(p1)
    print(
        f"P1, neutral, {NEUTRAL_LOAD_N:g} N: contact force on " + ", ".join(f"{k} {v:.1f} N" for k, v in forces.items())
    )


if __name__ == "__main__":
    main()
