"""Synthetic "4DCT" trials: a hidden truth simulated on a finer model, with tracking noise.

No 4DCT ships with wrist-env. A built-in participant's trials (and, with issue 55, each instance's)
are made so, for its Table 1 task (P1 radial–ulnar deviation, P2 grip, P3 flexion–extension): an
unresisted (calibration) and a resisted (validation) trial of `N_FRAMES` frames, one motion cycle
(extremum → other extremum → back):

1. the capitate's rotations follow the task (`capitate_motion`: Cardan Z-X-Y angles); its
   translations, and the radial column, are free under the tendon lines (`settings.DEFAULT_LOADS`)
   at a total of 10 N unresisted, 40 N resisted (grip clenches from 10 N to 60 N / 120 N), the
   load each frame records;
2. the carpals come from a higher-fidelity run of the model — finer contact sampling
   (`HIGH_FIDELITY_BUILD`: 0.7 mm instead of 1.0 mm), half the time step, a ten times tighter
   equilibrium tolerance and force floor, holds up to 6,400 steps (`HIGH_FIDELITY_SOLVER`) — with
   the hidden true ligament design;
3. every tracked carpal (`model.CARPALS`) gets 4DCT-like tracking noise (`builtin.tracking_noise`:
   a rigid perturbation about its centroid, 0.2 mm and 0.5° RMS).

So the default model never fits a trial exactly: the fidelity gap and the noise are real.
Deterministic for a given model, truth and seed. `experiments/authoring/make_trials.py` writes the
built-ins' files with it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from wrist_env.builder.params import BuildParams
from wrist_env.design import Design
from wrist_env.errors import BuildError
from wrist_env.frames import cardan_rotation
from wrist_env.model import BONES, CARPALS
from wrist_env.participants.builtin import tracking_noise
from wrist_env.participants.registry import load_model
from wrist_env.solver.drivers import loaded
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import simulate
from wrist_env.trial import Trial

__all__ = [
    "HIGH_FIDELITY_BUILD",
    "HIGH_FIDELITY_SOLVER",
    "N_FRAMES",
    "TRIALS",
    "TrialsRefused",
    "capitate_motion",
    "synthetic_trials",
]

N_FRAMES = 15
"""Frames of each synthetic trial: one motion cycle."""
HIGH_FIDELITY_BUILD = BuildParams(contact_spacing_mm=0.7)
"""The finer model the truth is simulated on (contact samples 0.7 mm apart instead of 1.0 mm)."""
HIGH_FIDELITY_SOLVER = replace(
    SolverSettings().diagonal().halved(), tolerance=1e-4, force_floor_n=1e-3, max_hold_steps=6400
)
"""The truth's solver: the diagonal mass at half the time step, equilibrium ten times tighter."""
LOAD_N = {"unresisted": 10.0, "resisted": 40.0}
"""Each trial's total tendon load (N), unresisted and resisted."""
GRIP_PEAK_N = {"unresisted": 60.0, "resisted": 120.0}
"""The grip task's peak load (N): it clenches from `LOAD_N["unresisted"]` to this and back."""
ROLE = {"unresisted": "calibrate", "resisted": "validate"}
TRIALS = tuple(ROLE)
"""The synthetic trials, in order: the unresisted one calibrates, the resisted one validates."""


class TrialsRefused(BuildError):
    """A truth whose higher-fidelity run fails cannot make a trial."""


def cycle() -> np.ndarray:
    """Phase of each frame, 0 → 2π: extremum (frame 0) → other extremum (frame 7) → back."""
    return np.linspace(0.0, 2.0 * np.pi, N_FRAMES)


def capitate_motion(task: str, trial: str) -> tuple[np.ndarray, np.ndarray]:
    """The capitate's rotations and the tendon load of a task's trial, frame by frame.

    Parameters
    ----------
    task : str
        "flexion-extension", "radial-ulnar deviation" or "grip" (Table 1).
    trial : str
        "unresisted" or "resisted" (`TRIALS`).

    Returns
    -------
    angles : np.ndarray, shape (N_FRAMES, 3)
        The capitate's Cardan Z-X-Y angles, deg: flexion, ulnar deviation, pronation.
    load : np.ndarray, shape (N_FRAMES,)
        The total tendon load, N.

    Raises
    ------
    ValueError
        An unknown task.
    """
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


def synthetic_trials(name: str, task: str, truth: Design, seed: int) -> tuple[dict[str, Trial], dict]:
    """A participant's synthetic trials, made from a hidden truth for its task.

    Parameters
    ----------
    name : str
        The participant, whose model (built at `HIGH_FIDELITY_BUILD`) simulates the truth.
    task : str
        Its Table 1 task (see `capitate_motion`).
    truth : Design
        The hidden true ligament design.
    seed : int
        The seed of the tracking noise (`np.random.default_rng(seed)`).

    Returns
    -------
    trials : dict of str to Trial
        Trial name → Trial (every body, `load_n` recorded).
    record : dict
        Per trial: its task, role, the capitate's angles (deg), loads (N), solver steps and largest residual
        (N).

    Raises
    ------
    TrialsRefused
        The truth's run fails (the message names the participant, the trial and the solver's message).
    """
    model = load_model(name, HIGH_FIDELITY_BUILD)
    rng = np.random.default_rng(seed)
    trials, record = {}, {}
    for trial in TRIALS:
        angles, load = capitate_motion(task, trial)
        result = simulate(model, truth, loaded(model, cardan_rotation(angles), load), HIGH_FIDELITY_SOLVER)
        if not result.ok:
            raise TrialsRefused(f"{name} {trial}: the high-fidelity run of the truth failed: {result.message}")
        poses = np.transpose(result.poses, (1, 0, 2, 3)).copy()  # (bone, frame, 4, 4)
        for b in CARPALS:
            i = BONES.index(b)
            poses[i] = tracking_noise(poses[i], model.centroid[i], rng)
        trials[trial] = Trial(trial, ROLE[trial], BONES, poses, load_n=load.round(3))  # as trials.json keeps it
        record[trial] = {
            "role": ROLE[trial],
            "task": task,
            "capitate_cardan_deg": angles.round(3).tolist(),
            "load_n": load.round(3).tolist(),
            "steps": int(result.steps.sum()),
            "max_residual_n": float(result.residual[:, 0].max()),
        }
    return trials, record
