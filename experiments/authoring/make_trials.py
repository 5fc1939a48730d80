"""Author the built-in participants' trials: synthetic "4DCT" kinematics, and say so.

No 4DCT ships with wrist-env. For each built-in participant (Table 1 task:
P1 radial–ulnar deviation, P2 grip, P3 flexion–extension) this script writes
an unresisted (calibration) and a resisted (validation) trial of 15 frames,
one motion cycle (extremum → other extremum → back), as CSV of 4×4
transforms per bone per frame (RCS, mm):

1. the capitate's rotations follow the task (Cardan Z-X-Y angles below);
   its translations, and the radial column, are free under the tendon lines
   (`settings.DEFAULT_LOADS`) at a total of 10 N unresisted, 40 N resisted
   (grip clenches from 10 N to 60 N / 120 N), the load each frame records;
2. the scaphoid and lunate come from a higher-fidelity run of the model —
   finer contact sampling (0.7 mm instead of 1.0 mm), half the time step,
   a ten times tighter equilibrium tolerance and force floor, holds up to
   6,400 steps — with the participant's
   hidden true ligament properties (`builtin.truth`);
3. every carpal bone gets 4DCT-like tracking noise: a rigid perturbation
   about its centroid, 0.2 mm and 0.5° RMS.

So the default model never fits a trial exactly: the fidelity gap and the
noise are real. Deterministic (seeded by the participant's truth seed).
Run: `python experiments/authoring/make_trials.py` (a few minutes: it builds the
higher-fidelity models first).
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from wrist_env.builder.params import BuildParams
from wrist_env.frames import cardan_rotation
from wrist_env.model import BONES
from wrist_env.participants import builtin
from wrist_env.participants.registry import load_model
from wrist_env.solver.drivers import loaded
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import simulate
from wrist_env.trial import Trial, write_trial_csv

DATA = Path(__file__).resolve().parents[2] / "wrist_env" / "participants" / "data"
N_FRAMES = 15
HIGH_FIDELITY_BUILD = BuildParams(contact_spacing_mm=0.7)
HIGH_FIDELITY_SOLVER = replace(
    SolverSettings().diagonal().halved(), tolerance=1e-4, force_floor_n=1e-3, max_hold_steps=6400
)
NOISE_MM, NOISE_DEG = builtin.TRACKING_NOISE_MM, builtin.TRACKING_NOISE_DEG
LOAD_N = {"unresisted": 10.0, "resisted": 40.0}
GRIP_PEAK_N = {"unresisted": 60.0, "resisted": 120.0}
ROLE = {"unresisted": "calibrate", "resisted": "validate"}


def cycle() -> np.ndarray:
    """Phase of each frame, 0 → 2π: extremum (frame 0) → other extremum (frame 7) → back."""
    return np.linspace(0.0, 2.0 * np.pi, N_FRAMES)


def capitate_motion(task: str, trial: str):
    """(Cardan Z-X-Y angles (15, 3) deg: flexion, ulnar deviation, pronation; load (15,) N)."""
    phi = cycle()
    half = 0.5 * (1.0 - np.cos(phi))  # 0 → 1 → 0
    angles = np.zeros((N_FRAMES, 3))
    load = np.full(N_FRAMES, LOAD_N[trial])
    if task == "flexion-extension":  # 40° flexion → 40° extension → back, slight dart-throw coupling
        angles[:, 0] = 40.0 * np.cos(phi)
        angles[:, 1] = -4.0 * np.cos(phi)
    elif task == "radial-ulnar deviation":  # 15° radial → 25° ulnar → back, the row flexing in radial deviation
        angles[:, 1] = -15.0 + 40.0 * half
        angles[:, 0] = 5.0 - 10.0 * half
    elif task == "grip":  # a clench: little rotation, the joint load rising and falling
        angles[:, 0] = -8.0 * half
        angles[:, 1] = 3.0 * half
        load = LOAD_N["unresisted"] + (GRIP_PEAK_N[trial] - LOAD_N["unresisted"]) * half
    else:
        raise ValueError(f"unknown task {task!r}")
    return angles, load


def make(name: str) -> dict:
    info = builtin.info(name)
    model = load_model(name, HIGH_FIDELITY_BUILD)
    truth = builtin.truth(name)
    seed = json.loads((DATA / name / "participant.json").read_text())["truth_seed"]
    rng = np.random.default_rng(seed + 1000)
    out = {}
    folder = DATA / name / "trials"
    folder.mkdir(exist_ok=True)
    for trial in ("unresisted", "resisted"):
        angles, load = capitate_motion(info.task, trial)
        result = simulate(model, truth, loaded(model, cardan_rotation(angles), load), HIGH_FIDELITY_SOLVER)
        if not result.ok:
            raise RuntimeError(f"{name} {trial}: the high-fidelity run failed: {result.message}")
        poses = np.transpose(result.poses, (1, 0, 2, 3)).copy()  # (bone, frame, 4, 4)
        for b in ("scaphoid", "lunate", "capitate"):
            i = BONES.index(b)
            poses[i] = builtin.tracking_noise(poses[i], model.centroid[i], rng)
        t = Trial(trial, ROLE[trial], BONES, poses)
        write_trial_csv(t, folder / f"{trial}.csv")
        out[trial] = {
            "file": f"trials/{trial}.csv",
            "role": ROLE[trial],
            "task": info.task,
            "capitate_cardan_deg": angles.round(3).tolist(),
            "load_n": load.round(3).tolist(),
            "steps": int(result.steps.sum()),
        }
        print(
            f"{name} {trial}: {info.task}, {int(result.steps.sum())} steps, max residual {result.residual[:, 0].max():.3f} N"
        )
    meta = {
        "synthetic": True,
        "frames": N_FRAMES,
        "noise_mm": NOISE_MM,
        "noise_deg": NOISE_DEG,
        "high_fidelity": {
            "contact_spacing_mm": HIGH_FIDELITY_BUILD.contact_spacing_mm,
            "dt_s": HIGH_FIDELITY_SOLVER.dt_s,
            "tolerance": HIGH_FIDELITY_SOLVER.tolerance,
        },
        "trials": out,
    }
    (DATA / name / "trials.json").write_text(json.dumps(meta, indent=1) + "\n")
    return meta


if __name__ == "__main__":
    for participant in builtin.BUILTIN:
        make(participant)
