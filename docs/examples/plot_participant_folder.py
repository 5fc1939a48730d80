"""
A participant folder
====================

Your own wrist enters wrist-env as a folder: ``participant.toml``, five bone
meshes (mm, in the radius coordinate system, RCS) and trial CSVs (each
bone's 4×4 transform per frame). This example writes the built-in P1 as such
a folder (``wrist-bench export P1 DIR`` does the same), reads it back with
its checks, registers it, and looks at its bones and its calibration trial.
Building its model is shown, not run: a new participant's build takes about
a minute, and this page is built with the rest of the site.
"""

# %%
# Write a folder. ``builtin.source`` is P1 as a ``ParticipantSource`` (its
# bones, trials and Table 1 facts); renamed, it does not clash with the
# built-in.
import dataclasses
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd

from wrist_env.participants import builtin, registry
from wrist_env.participants.folder import write_participant_folder

p1 = builtin.source("P1")
root = Path(tempfile.mkdtemp(prefix="participant-"))
my_wrist = dataclasses.replace(p1, name="my_wrist")
folder = write_participant_folder(my_wrist, root / "my_wrist")
for path in sorted(folder.rglob("*")):
    print(path.relative_to(root))

# %%
# ``participant.toml`` names the bones' and trials' files and the trials'
# roles: exactly one trial calibrates, a ``validate`` trial is held out.
print((folder / "participant.toml").read_text())

# %%
# A trial CSV: one row per bone per frame, the top three rows of the 4×4
# transform from the static pose to that frame (RCS, mm).
trial_csv = pd.read_csv(folder / "trials" / "unresisted.csv")
print(trial_csv.head(6).to_string(index=False))

# %%
# Registering reads and checks the folder once: every mesh closed and in one
# piece, in millimetres, one file per bone; every trial's frames complete,
# its rotations orthonormal, the radius at the identity. The participant is
# then known by name, beside the built-ins.
name = registry.add_folder(folder)
print(name, "registered; participants:", registry.participants())

# %%
# A folder that breaks a rule is refused with the file and the value. Here
# the scaphoid written in metres instead of millimetres:
import trimesh

from wrist_env.errors import WristEnvError

in_metres = dataclasses.replace(p1, name="in_metres")
bad = write_participant_folder(in_metres, root / "in_metres")
mesh = trimesh.load(bad / "bones" / "scaphoid.stl")
mesh.apply_scale(1e-3)
mesh.export(bad / "bones" / "scaphoid.stl")
try:
    registry.add_folder(bad)
except WristEnvError as error:
    print(type(error).__name__, ":", error)

# %%
# The bones as the folder gives them (every 20th vertex, seen from the
# volar side: RCS z radial, y proximal) and the calibration trial's scaphoid
# and lunate flexion, frame by frame (Cardan angles about the RCS z axis).
from wrist_env.frames import DOF_NAMES, pose_to_dof

trial = registry.trial(name, "calibrate")
fig, (ax_bones, ax_trial) = plt.subplots(1, 2, figsize=(9, 4))
for bone, (vertices, faces) in p1.bones.items():
    ax_bones.plot(vertices[::20, 2], vertices[::20, 1], ".", ms=1, label=bone)
ax_bones.set(xlabel="z (mm, radial +)", ylabel="y (mm, proximal +)", aspect="equal")
ax_bones.set_title("bones, volar view")
ax_bones.legend(markerscale=8, fontsize=8)
flexion = DOF_NAMES.index("Flex/Ext")
for bone in ("scaphoid", "lunate", "capitate"):
    ax_trial.plot(pose_to_dof(trial.pose(bone))[:, flexion], label=bone)
ax_trial.set(xlabel="frame", ylabel="flexion (deg)")
ax_trial.set_title(f"{name}'s calibration trial")
ax_trial.legend()
fig.tight_layout()

# %%
# The build, shown and not run here (a new participant's model takes about
# a minute to build; it is cached afterwards under a key of its bones and
# the build parameters):
#
# .. code-block:: python
#
#    model = registry.load_model("my_wrist")  # wrist-bench build my_wrist --folder DIR
#
#    import gymnasium as gym
#    import wrist_env
#
#    ids = wrist_env.register_participant(folder)  # Calibrate-, Validate-, Idealized-
#    env = gym.make(ids[0])
#    obs, info = env.reset(seed=0)
#    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
