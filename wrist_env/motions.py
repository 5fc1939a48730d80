"""The motions a participant is simulated through: its trials' roles and the idealized sweep (a module of
names only, so that the command line declares its choices without loading a trial's reader)."""

TRIAL_MOTIONS = ("calibrate", "validate")
"""The two trials of a participant that calibration uses: the unresisted one it fits and the resisted one it
is judged on."""
MOTIONS = TRIAL_MOTIONS + ("idealized",)
"""Every motion a task drives: the two trials and the idealized flexion–extension sweep."""
