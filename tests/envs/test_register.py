"""A user's participant folder through `wrist_env.register_participant`: Gymnasium ids that build and
step, and bad trials rejected with an error naming the file."""

import importlib.resources
import importlib.util
import json
import math
import re
import shutil
from pathlib import Path

import gymnasium as gym
import numpy as np
import pandas as pd
import pytest

import wrist_env
from wrist_env.cli import main
from wrist_env.envs import env_id
from wrist_env.errors import TrialError
from wrist_env.participants import registry

P1_TRIALS = importlib.resources.files("wrist_env.participants") / "data" / "P1" / "trials"


def _warped_template_folder():
    """tests/participants/test_registry.py's folder of warped template bones (tests are not a package)."""
    path = Path(__file__).parents[1] / "participants" / "test_registry.py"
    spec = importlib.util.spec_from_file_location("_participant_registry_tests", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.warped_template_folder


def make_folder(path, name: str, validate: bool) -> Path:
    """Warped template bones; P1's unresisted trial as "calibrate", and its resisted one as "validate"."""
    folder = _warped_template_folder()(path, name=name)
    shutil.copyfile(P1_TRIALS / "unresisted.csv", folder / "trials" / "unresisted.csv")
    if validate:
        shutil.copyfile(P1_TRIALS / "resisted.csv", folder / "trials" / "resisted.csv")
        with open(folder / "participant.toml", "a", encoding="utf-8") as f:
            f.write('\n[trials.resisted]\nfile = "trials/resisted.csv"\nrole = "validate"\n')
    return folder


@pytest.fixture(scope="module")
def calibrate_only(tmp_path_factory):
    return make_folder(tmp_path_factory.mktemp("reg") / "ua", "UA", validate=False)


@pytest.fixture(scope="module")
def with_validate(tmp_path_factory):
    """The one folder whose model is built (20–60 s) into conftest's session cache. Its bones and name
    are test_registry.py's "U1" (no other part of a folder enters the cache key), so a session builds it once."""
    return make_folder(tmp_path_factory.mktemp("reg") / "u1", "U1", validate=True)


def test_calibrate_only_folder_registers_calibrate_and_idealized(calibrate_only):
    ids = wrist_env.register_participant(calibrate_only)
    assert ids == ("wrist_env/Calibrate-UA-v0", "wrist_env/Idealized-UA-v0")
    assert set(ids) <= set(wrist_env.registered_ids()) and env_id("UA", "validate") not in gym.registry
    assert wrist_env.register_participant(calibrate_only) == ids  # registering again is harmless


def test_registered_ids_make_and_step(with_validate):
    ids = wrist_env.register_participant(with_validate)
    assert ids == tuple(env_id("U1", m) for m in ("calibrate", "validate", "idealized"))
    for i in ids:
        env = gym.make(i)
        obs, _ = env.reset(seed=0)
        _, reward, terminated, truncated, info = env.step(np.zeros(27, dtype=np.float32))
        assert terminated and not truncated, i
        assert math.isfinite(reward) and not info["failed"], (i, reward, info["status"])
        if "Idealized" in i:
            assert reward == 0.0  # a user participant's sweep has no reference kinematics
        else:
            assert reward < 0.0 and math.isfinite(info["cost"])


@pytest.mark.slow
def test_a_folder_participants_idealized_info_has_the_builtins_keys(with_validate):
    """A folder participant's idealized sweep has no reference kinematics (reward 0): its info has the
    keys of a scored run's, cost, error_p75, rmse and cost_terms None (they were missing, and
    `sensitivity` failed with KeyError: 'error_p75'); the vector env's infos carry them too."""
    from wrist_env.task import REFERENCE_KEYS

    wrist_env.register_participant(with_validate)
    infos = {}
    for motion in ("calibrate", "idealized"):
        env = gym.make(env_id("U1", motion))
        env.reset(seed=0)
        _, reward, *_, infos[motion] = env.step(np.zeros(27, dtype=np.float32))
    assert set(infos["idealized"]) == set(infos["calibrate"]) and reward == 0.0
    assert all(infos["idealized"][k] is None for k in REFERENCE_KEYS)
    assert math.isfinite(infos["calibrate"]["cost"]) and infos["calibrate"]["error_p75"]["lunate"]
    vector = gym.make_vec(env_id("U1", "idealized"), num_envs=2, vectorization_mode="vector_entry_point")
    vector.reset(seed=0)
    *_, vinfo = vector.step(np.zeros((2, 27), dtype=np.float32))
    assert set(REFERENCE_KEYS) <= set(vinfo) and list(vinfo["error_p75"]) == [None, None]


def test_evaluate_command_with_folder(capsys, with_validate):
    assert main(["evaluate", "U1", "--folder", str(with_validate), "--motion", "validate", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["participant"] == "U1" and out["motion"] == "validate" and not out["failed"]
    assert math.isfinite(out["cost"]) and out["cost"] > 0
    assert main(["evaluate", "U1", "--folder", str(with_validate), "--design", "truth"]) == 2
    assert "--design truth needs a built-in participant" in capsys.readouterr().err


def _nan(t):
    return t.assign(m01=np.where((t.frame == 3) & (t.bone == "lunate"), np.nan, t.m01))


def _non_orthonormal(t):
    return t.assign(m00=np.where((t.frame == 4) & (t.bone == "scaphoid"), t.m00 * 1.01, t.m00))


def _no_capitate(t):
    return t[t.bone != "capitate"]


@pytest.mark.parametrize(
    "edit, message",
    [
        (_nan, "finite.*bone 'lunate' frame 3 has m01=nan"),
        (_non_orthonormal, "orthonormal.*bone 'scaphoid' frame 4"),
        (_no_capitate, r"\['capitate'\] are missing"),
        ("frames", "n_frames=12 frames, but has 15"),
    ],
    ids=["nan", "non_orthonormal", "missing_bone", "frames"],
)
def test_bad_trial_is_rejected_naming_the_file(tmp_path, calibrate_only, edit, message):
    """test_trial.py checks these rules on read_trial_csv; here they reach register_participant."""
    folder = shutil.copytree(calibrate_only, tmp_path / "bad")
    toml = folder / "participant.toml"
    toml.write_text(toml.read_text().replace('name = "UA"', 'name = "UBAD"'))
    csv = folder / "trials" / "unresisted.csv"
    if edit == "frames":
        toml.write_text(toml.read_text().replace('units = "mm"', 'units = "mm"\nframes = 12'))
    else:
        edit(pd.read_csv(csv)).to_csv(csv, index=False, float_format="%.17g")
    with pytest.raises(TrialError, match=f"(?s){re.escape(str(csv))}.*{message}"):
        wrist_env.register_participant(folder)
    assert "UBAD" not in registry.participants()
    assert not any("-UBAD-" in i for i in wrist_env.registered_ids())
