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


def _trials_digest(made: instances.Instance) -> str:
    """16 hex digits of an instance's trials: every pose to 0.001 (mm; rotation entries) and every load (N)."""
    h = hashlib.sha256()
    for name in sorted(made.trials):
        trial = made.trials[name]
        h.update(name.encode())
        h.update(np.round(trial.transforms, 3).tobytes())
        h.update(np.round(trial.load_n, 3).tobytes())
    return h.hexdigest()[:16]


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


def test_a_drawn_instance_is_the_same_problem_on_every_machine(built, tmp_path, monkeypatch):
    """Instance 1 of P1 is pinned by what makes it, each part where it is cheap to check: its truth (pinned
    above); the finer model its trials are simulated on, by its source hash in the instance's key (the bones,
    the build parameters, the builder's and the annotations' versions: `registry.model_source_hash`, nothing
    built) — that a build of the same inputs gives the same model is tests/participants/test_registry.py's
    rebuild of P1 against its shipped model; and the making itself — the truth's two trials simulated with
    the truth's solver and tracking noise, written and read back — run here on P1's shipped model instead of
    the finer one (a build of a minute), its trials' digest pinned. A change to any of them changes instance
    1: raise `instances.VERSION` and pin anew."""
    from wrist_env.participants import synthetic

    assert instances.instance_key("P1", 1) == "b12045d2f513c3b5"
    monkeypatch.setenv("WRIST_ENV_CACHE", str(tmp_path))
    shipped = built("P1")
    monkeypatch.setattr(synthetic, "load_model", lambda name, params=None: shipped)
    instances.instance.cache_clear()
    try:
        made = instances.instance("P1", 1)
    finally:
        instances.instance.cache_clear()
    assert sorted(made.trials) == ["resisted", "unresisted"]
    assert all(t.transforms.shape == (len(t.bones), 15, 4, 4) for t in made.trials.values())
    assert _trials_digest(made) == "3663e1ff1f077e3b"


@pytest.mark.parametrize("bad", [-1, MAX_INSTANCE + 1, 1.5, True, "1"])
def test_a_bad_instance_is_refused(bad):
    with pytest.raises(ParticipantError, match=f"instance must be an integer in \\[0, {MAX_INSTANCE:,}\\], but got"):
        instances.truth("P1", bad)


def test_instances_are_built_in_participants_only():
    with pytest.raises(ParticipantError, match="built-in participant's task"):
        instances.truth("U1", 1)


@pytest.fixture
def cheap_maker(tmp_path, monkeypatch):
    """Instances made into tmp_path without the finer model: `synthetic_trials` stands in with the shipped
    trials (the calls it gets are counted), and the key without the finer model's hash."""
    from wrist_env.participants import synthetic

    monkeypatch.setenv("WRIST_ENV_CACHE", str(tmp_path))
    monkeypatch.setattr(instances, "instance_key", lambda name, k: f"{k:016d}")
    calls = []

    def trials(name, task, truth, seed):
        calls.append((name, seed))
        shipped = builtin.trials(name)
        return dict(shipped), {t: {"role": shipped[t].role, "load_n": shipped[t].load_n.tolist()} for t in shipped}

    monkeypatch.setattr(synthetic, "synthetic_trials", trials)
    instances.instance.cache_clear()
    yield calls
    instances.instance.cache_clear()


def test_an_instance_is_made_once_then_read_from_its_folder(cheap_maker, tmp_path):
    made = instances.instance("P1", 2)
    instances.instance.cache_clear()
    read = instances.instance("P1", 2)
    assert len(cheap_maker) == 1  # the second call read the folder
    folder = tmp_path / "instances" / f"P1-2-{2:016d}"
    assert sorted(p.name for p in folder.iterdir()) == sorted(
        ["truth.json", "instance.json", *(f"{t}.csv" for t in made.trials)]
    )
    assert np.allclose(read.truth.vector, instances.truth("P1", 2).vector, rtol=1e-12)
    for t, trial in made.trials.items():  # the CSV round trip keeps the poses to its written precision
        assert np.allclose(read.trials[t].transforms, trial.transforms, atol=1e-6)
        assert np.array_equal(read.trials[t].load_n, trial.load_n)
    assert read.trial("calibrate").role == "calibrate" and read.trial("validate").role == "validate"


def test_an_instance_whose_truth_cannot_make_a_trial_is_refused_by_name(cheap_maker, tmp_path, monkeypatch):
    from wrist_env.participants import synthetic

    def refused(name, task, truth, seed):
        raise synthetic.TrialsRefused(f"{name} calibrate: the high-fidelity run of the truth failed: diverged")

    monkeypatch.setattr(synthetic, "synthetic_trials", refused)
    with pytest.raises(synthetic.TrialsRefused, match="instance 3 of P2 cannot be made .*diverged"):
        instances.instance("P2", 3)
    assert not list((tmp_path / "instances").glob("P2-3-*"))  # nothing half-made left to be read
