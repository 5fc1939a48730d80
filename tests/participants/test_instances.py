"""Problem instances (issue 55): instance 0 is the shipped problem, instance k a fixed draw."""

import hashlib

import numpy as np
import pytest

from wrist_env import design
from wrist_env.errors import ParticipantError
from wrist_env.limits import MAX_INSTANCE
from wrist_env.participants import builtin, instances, registry


def _digest(d: design.Design) -> str:
    return hashlib.sha256(np.round(d.vector, 9).tobytes()).hexdigest()[:16]


def test_instance_zero_is_the_shipped_problem():
    zero = instances.instance("P1", 0)
    assert np.array_equal(zero.truth.vector, builtin.truth("P1").vector)
    assert zero.trials.keys() == builtin.trials("P1").keys()
    assert np.array_equal(zero.trial("calibrate").transforms, registry.trial("P1", "calibrate").transforms)


def test_a_drawn_truth_is_fixed_intact_and_within_the_prior():
    """The same on every machine: its digest pinned (a change to `instances.seeds`, `ENTROPY` or the prior's
    draw changes every instance: raise `instances.VERSION` and pin anew)."""
    one = instances.truth("P1", 1)
    assert (_digest(one), _digest(instances.truth("P2", 3))) == ("c41b65278a34c502", "d7413412e61c5575")
    assert _digest(one) != _digest(instances.truth("P1", 2)) != _digest(instances.truth("P2", 1))
    action = design.to_action(one)
    assert np.allclose(
        action[design.N_MATERIAL :], [design.INTACT_INJURY[n] for n in design.NAMES[design.N_MATERIAL :]]
    )
    assert np.all(np.abs(action[: design.N_MATERIAL]) <= 1.0)  # Table 2's normals truncated at ±3 SD: the action box


@pytest.mark.parametrize("bad", [-1, MAX_INSTANCE + 1, 1.5, True, "1"])
def test_a_bad_instance_is_refused(bad):
    with pytest.raises(ParticipantError, match=f"instance must be an integer in \\[0, {MAX_INSTANCE:,}\\], but got"):
        instances.truth("P1", bad)


def test_instances_are_built_in_participants_only():
    with pytest.raises(ParticipantError, match="built-in participant's task"):
        instances.truth("U1", 1)
