"""The motions a participant is simulated through: its trials' roles, the idealized sweep and the capitate held
at neutral (a module of names only, so that the command line declares its choices without loading a trial's
reader). `solver.drivers.for_motion` is the one map from these names to drivers."""

TRIAL_MOTIONS = ("calibrate", "validate")
"""The two trials of a participant that calibration uses: the unresisted one it fits and the resisted one it
is judged on."""
IDEALIZED = "idealized"
"""The idealized flexion–extension sweep (preprint 2.2.3.2): the capitate's rotation prescribed, its translations
free under a small compressive load."""
STATIC = "static"
"""The capitate held at neutral in all 6 DOF, no load: a model's rest pose (no reference kinematics)."""
MOTIONS = TRIAL_MOTIONS + (IDEALIZED,)
"""Every motion a task drives and scores: the two trials and the idealized flexion–extension sweep."""
DRIVEN_MOTIONS = MOTIONS + (STATIC,)
"""Every motion a simulation can be driven through (`wrist-bench simulate --motion`)."""
