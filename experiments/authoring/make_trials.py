"""Author the built-in participants' trials: synthetic "4DCT" kinematics, and say so.

For each built-in participant this writes its unresisted (calibration) and resisted (validation)
trials, made from its hidden truth (`builtin.truth`) by `wrist_env.participants.synthetic` (the
task's capitate motion under the tendon lines, a higher-fidelity run of the model, 4DCT-like tracking
noise), as CSV of 4×4 transforms per bone per frame (RCS, mm), and `trials.json` recording how.
Deterministic: the noise is seeded by the participant's truth seed + 1000.

Run: `python experiments/authoring/make_trials.py [P1 P2 P3]` (a few minutes: it builds the
higher-fidelity models first).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from wrist_env.participants import builtin, synthetic
from wrist_env.trial import write_trial_csv

DATA = Path(__file__).resolve().parents[2] / "wrist_env" / "participants" / "data"
NOISE_SEED_OFFSET = 1000
"""The tracking noise's seed: the participant's truth seed plus this (the truth's own draw used the seed)."""


def make(name: str) -> dict:
    """Write `name`'s trial CSVs and trials.json; returns the record."""
    seed = json.loads((DATA / name / "participant.json").read_text())["truth_seed"]
    trials, record = synthetic.synthetic_trials(
        name, builtin.info(name).task, builtin.truth(name), seed + NOISE_SEED_OFFSET
    )
    folder = DATA / name / "trials"
    folder.mkdir(exist_ok=True)
    for trial, t in trials.items():
        write_trial_csv(t, folder / f"{trial}.csv")
        record[trial] = {"file": f"trials/{trial}.csv", **record[trial]}
        print(
            f"{name} {trial}: {record[trial]['task']}, {record[trial]['steps']} steps, max residual {record[trial]['max_residual_n']:.3f} N"
        )
    meta = {
        "synthetic": True,
        "frames": synthetic.N_FRAMES,
        "noise_mm": builtin.TRACKING_NOISE_MM,
        "noise_deg": builtin.TRACKING_NOISE_DEG,
        "high_fidelity": {
            "contact_spacing_mm": synthetic.HIGH_FIDELITY_BUILD.contact_spacing_mm,
            "dt_s": synthetic.HIGH_FIDELITY_SOLVER.dt_s,
            "tolerance": synthetic.HIGH_FIDELITY_SOLVER.tolerance,
        },
        "trials": record,
    }
    (DATA / name / "trials.json").write_text(json.dumps(meta, indent=1) + "\n")
    return meta


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("participants", nargs="*", default=list(builtin.BUILTIN))
    for participant in parser.parse_args().participants:
        make(participant)
