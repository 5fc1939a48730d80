"""Where each injury moves the load in the Monte Carlo study's sweep (issue 33: Table 5's signs).

For each participant, the population design intact and with each injury scalar of the Monte Carlo
study torn (`montecarlo.sampler.TORN_ACTION`, one at a time), simulated on the study's driver (the
idealized ±40° sweep under its load on the default lines), this prints the sweep's means of the
radioscaphoid mean pressure (MPa, the study's response) and contact area (mm²), the contact forces (N) of the radioscaphoid,
radiolunate, STT, scaphocapitate, lunocapitate and ulnocarpal pairs, and the scaphoid's and lunate's
flexion slopes, each as the change from intact. Table 5 compares the study's estimates with the
preprint's; this says through which joints an injury's estimate arises. For each injury it then says
where the torn ligament's load goes: its intact mean tension over the sweep and the largest changes of
the other ligaments' tensions and of the contact forces, and the sign of the radioscaphoid pressure's
change beside the preprint's Table 5 estimate and the study's (`leaderboards/montecarlo/summary.json`,
when there) — the probe behind each sign that differs (issue 54, step 9).

Run: `python experiments/research/injury_load_paths.py [P1 P2] [--out FILE.md]` (seconds); the
regeneration writes `leaderboards/montecarlo/injury_load_paths.md`, which the Monte Carlo results page
shows below the study's report.
"""

from __future__ import annotations

import argparse
import json
import subprocess
from pathlib import Path

import numpy as np

from wrist_env import design, ligaments
from wrist_env.model import BONES, PAIRS
from wrist_env.montecarlo.report import PREPRINT_TABLE5
from wrist_env.montecarlo.sampler import INTACT_ACTION, TORN_ACTION
from wrist_env.participants.registry import load_model
from wrist_env.solver.drivers import idealized
from wrist_env.solver.forces import R_AREA, R_FORCE, R_MEAN
from wrist_env.solver.outputs import cardan_deg
from wrist_env.solver.simulate import simulate_batch
from wrist_env.validation import slope

SHOWN = ("radioscaphoid", "radiolunate", "scaphotrapezial", "scaphocapitate", "lunocapitate", "ulnocarpal")


def flexion_slopes(poses: np.ndarray) -> tuple[float, float]:
    """The scaphoid's and lunate's flexion per degree of the capitate's over a sweep (`validation.slope`)."""
    flex = cardan_deg(poses)[..., 0]
    cap = flex[:, BONES.index("capitate")]
    return slope(cap, flex[:, BONES.index("scaphoid")]), slope(cap, flex[:, BONES.index("lunate")])


def designs() -> dict[str, design.Design]:
    """The population design intact and with each injurable ligament torn, by name."""
    out = {"intact": design.population()}
    for i, name in enumerate(ligaments.INJURABLE):
        a = design.to_action(design.population())
        a[design.N_MATERIAL :] = INTACT_ACTION
        a[design.N_MATERIAL + i] = TORN_ACTION
        out[f"{name} torn"] = design.from_action(a)
    return out


ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "leaderboards" / "montecarlo" / "summary.json"
MOVED = 3
"""How many of the largest changes (ligament tensions, contact forces) an injury's line names."""


def study_estimates(path: Path = STUDY) -> dict:
    """The Monte Carlo study's Table 5 injury estimates (term -> MPa) from its summary, or {} without one."""
    if not path.is_file():
        return {}
    rows = json.loads(path.read_text())["beside_preprint"]["table5"]
    return {r["term"]: r["estimate"] for r in rows}


def probe(name: str) -> dict:
    """Per case (intact, each injury torn): the sweep's means of the RS mean pressure, the RS area, every
    pair's force and every bundle's tension, and the two flexion slopes; None for a failed run."""
    model = load_model(name)
    cases = designs()
    out = {}
    for case, r in zip(cases, simulate_batch(model, list(cases.values()), idealized(model))):
        if not r.ok:
            out[case] = None
            continue
        out[case] = {
            "rs_pressure": float(np.nanmean(r.contact[:, PAIRS.index("radioscaphoid"), R_MEAN])),
            "rs_area": float(np.mean(r.contact[:, PAIRS.index("radioscaphoid"), R_AREA])),
            "pairs": {p: float(np.mean(r.contact[:, i, R_FORCE])) for i, p in enumerate(PAIRS)},
            "bundles": dict(zip(ligaments.ALL_LIGAMENT_NAMES, np.mean(r.bundle_force, axis=0).astype(float))),
            "slopes": flexion_slopes(r.poses),
        }
    return out


def _largest(changes: dict, k: int = MOVED) -> str:
    top = sorted(changes.items(), key=lambda kv: -abs(kv[1]))[:k]
    return ", ".join(f"{n} {v:+.1f} N" for n, v in top)


def _sign(x: float) -> str:
    return "rises" if x > 0 else "falls" if x < 0 else "stays"


def report(name: str, rows: dict, study: dict) -> list[str]:
    """The participant's Markdown: the table of changes, then one line per injury on where its load goes."""
    base = rows["intact"]
    head = ["RS mean pressure (MPa)", "RS area (mm²)", *(f"{p} (N)" for p in SHOWN), "scaphoid slope", "lunate slope"]
    lines = [
        f"### {name}",
        "",
        "The population design, the Monte Carlo sweep; intact, then each injury's change.",
        "",
        "| | " + " | ".join(head) + " |",
        "|---|" + "---|" * len(head),
    ]
    for case, row in rows.items():
        if row is None:
            lines.append(f"| {case} | failed |" + " |" * (len(head) - 1))
            continue
        cells = [row["rs_pressure"], row["rs_area"], *(row["pairs"][p] for p in SHOWN), *row["slopes"]]
        if case != "intact":
            cells = np.subtract(
                cells, [base["rs_pressure"], base["rs_area"], *(base["pairs"][p] for p in SHOWN), *base["slopes"]]
            )
        fmt = "{:.3f}" if case == "intact" else "{:+.3f}"
        lines.append(f"| {case} | " + " | ".join(fmt.format(v) for v in cells) + " |")
    lines += ["", "Where each torn ligament's load goes (means over the sweep):", ""]
    for lig in ligaments.INJURABLE:
        row = rows[f"{lig} torn"]
        if row is None or base is None:
            lines.append(f"- **{lig}**: the run failed.")
            continue
        change = row["rs_pressure"] - base["rs_pressure"]
        others = {n: row["bundles"][n] - base["bundles"][n] for n in ligaments.ALL_LIGAMENT_NAMES if n != lig}
        pairs = {p: row["pairs"][p] - base["pairs"][p] for p in PAIRS}
        theirs = PREPRINT_TABLE5[lig][0]
        ours = study.get(lig)
        signs = [
            f"the preprint's estimate {theirs:+.3f} MPa ({'same sign' if np.sign(theirs) == np.sign(change) else 'the other sign'})"
        ]
        if ours is not None:
            signs.append(
                f"the study's {ours:+.3f} MPa ({'same sign' if np.sign(ours) == np.sign(change) else 'the other sign'})"
            )
        lines.append(
            f"- **{lig}** (intact tension {base['bundles'][lig]:.1f} N): the radioscaphoid mean pressure "
            f"{_sign(change)} by {abs(change):.3f} MPa (its force {row['pairs']['radioscaphoid'] - base['pairs']['radioscaphoid']:+.1f} N "
            f"over {row['rs_area'] - base['rs_area']:+.1f} mm² of contact); beside it {' and '.join(signs)}. The other ligaments: "
            f"{_largest(others)}; the contacts: {_largest(pairs)}."
        )
    return lines + [""]


def _commit() -> str:
    done = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    return done.stdout.strip() or "a worktree"


def main(names, out: Path | None = None) -> None:
    study = study_estimates()
    lines = [
        "## Where each injury moves the load",
        "",
        "Generated by `python experiments/research/injury_load_paths.py "
        f"{' '.join(names)}` at {_commit()}: the population design with one injury at a time (the study's "
        "torn value, the other injury scalars intact), the study's sweep and load. The study's estimate is "
        "an average over random designs and other tears; this probe shows the joints and ligaments through "
        "which one tear acts at the population design.",
        "",
    ]
    for name in names:
        lines += report(name, probe(name), study)
    text = "\n".join(lines)
    if out is None:
        print(text)
    else:
        Path(out).write_text(text)
        print(f"wrote {out}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("participants", nargs="*", default=["P1", "P2"])
    parser.add_argument("--out", type=Path, help="write the Markdown here instead of printing it")
    args = parser.parse_args()
    main(args.participants, args.out)
