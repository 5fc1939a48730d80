"""Fixtures of the benchmark's tests: instance 1 of P1 without the minutes its real making takes."""

from dataclasses import replace

import numpy as np
import pytest

from wrist_env.participants import instances
from wrist_env.task import task

MOVED_MM = 0.3
"""How far the stand-in instance's calibration trial moves the scaphoid and the lunate (x, mm)."""


@pytest.fixture
def p1_instance_1(built, monkeypatch):
    """P1's instance 1 as calibrations see it (`instances.instance`), made without building the finer model
    and simulating its trials (minutes): its drawn truth (`instances.truth`, as the real one), and the
    shipped trials with the calibration trial's scaphoid and lunate moved `MOVED_MM` — other trials than
    instance 0's, so a cost, a provenance or a score on them is told apart from instance 0's."""
    built("P1")
    shipped = instances.instance("P1", 0)
    calibrate = shipped.trial("calibrate")
    transforms = np.array(calibrate.transforms)
    for i, bone in enumerate(calibrate.bones):
        if bone in ("scaphoid", "lunate"):
            transforms[i, :, 0, 3] += MOVED_MM
    trials = {**shipped.trials, calibrate.name: replace(calibrate, transforms=transforms)}
    stand_in = instances.Instance("P1", 1, instances.truth("P1", 1), trials)
    real = instances.instance
    monkeypatch.setattr(instances, "instance", lambda name, k=0: stand_in if (name, k) == ("P1", 1) else real(name, k))
    task.cache_clear()  # no Task of instance 1 made before
    yield stand_in
    task.cache_clear()  # nor one of the stand-in kept after
