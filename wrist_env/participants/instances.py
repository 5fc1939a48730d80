"""Problem instances (issue 55): `(participant, instance)` names a calibration problem.

Instance 0 is a built-in participant's shipped truth and trials (`builtin.truth`, `builtin.trials`).
Instance k ≥ 1 draws its hidden truth from the population prior — Table 2's normals truncated at
±3 SD, as the Monte Carlo sampler draws materials (`table2.sample_materials`), every ligament intact
(a calibration problem, not an injury) — and makes its calibrate and validate trials as the
built-ins' are made (`synthetic.synthetic_trials`: the participant's task, the finer model, the
tracking noise). Both draws are seeded from (participant, k) alone (`seeds`), so instance k of a
participant is the same problem on every machine, as COCO's instances are.

An instance is made once and cached beside the models (`cache.cache_dir()/instances/`), in a
folder named by what it is made from (`instance_key`: the participant, k, the finer model's source
hash and `VERSION`), holding `truth.json`, the trials as CSV (`trial` format) and `instance.json`;
processes needing one at once make it once (a lock). A draw whose truth cannot make a trial is
refused (`synthetic.TrialsRefused`) naming the instance.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import shutil
import zlib
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from wrist_env import design, table2
from wrist_env.design import Design
from wrist_env.errors import ParticipantError
from wrist_env.io import read_json, write_json
from wrist_env.limits import MAX_INSTANCE
from wrist_env.participants import builtin, cache, registry
from wrist_env.trial import Trial, read_trial_csv, write_trial_csv

__all__ = ["ENTROPY", "VERSION", "Instance", "instance", "instance_key", "seeds", "truth"]

ENTROPY = 55_2026_12_07
"""The root of every instance's seeds (`seeds`): fixed, so that instance k is the same everywhere."""
VERSION = 1
"""How instances are drawn and made; raise it when that changes (the cache key includes it)."""


@dataclass(frozen=True, eq=False)
class Instance:
    """One calibration problem: a participant's hidden truth and the trials made from it.

    Parameters
    ----------
    participant : str
        A built-in participant's name.
    index : int
        The instance, k (0: the shipped truth and trials).
    truth : Design
        The hidden ligament design.
    trials : dict of str to Trial
        Trial name → Trial, one with role "calibrate", one "validate".
    """

    participant: str
    index: int
    truth: Design
    trials: dict[str, Trial]

    def trial(self, role: str) -> Trial:
        """The instance's trial with `role` ("calibrate" or "validate")."""
        return next(t for t in self.trials.values() if t.role == role)


def _check(name: str, k: int) -> None:
    if name not in builtin.BUILTIN:
        raise ParticipantError(
            f"instances draw a hidden truth and synthetic trials for a built-in participant's task "
            f"{builtin.BUILTIN}, but got {name!r}"
        )
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k <= MAX_INSTANCE:
        raise ParticipantError(f"instance must be an integer in [0, {MAX_INSTANCE:,}], but got {k!r}")


def seeds(name: str, k: int) -> tuple[np.random.SeedSequence, np.random.SeedSequence]:
    """The seeds of instance k ≥ 1 of a participant: its truth's and its tracking noise's.

    They are the two children of a `SeedSequence` of (`ENTROPY`, the CRC-32 of the name, k).

    Parameters
    ----------
    name : str
        The participant, whose name (not its model) seeds the draw.
    k : int
        The instance, ≥ 1.

    Returns
    -------
    truth_seed, noise_seed : np.random.SeedSequence
        The truth's seed and the tracking noise's seed.
    """
    root = np.random.SeedSequence([ENTROPY, zlib.crc32(name.encode()), int(k)])
    truth_seed, noise_seed = root.spawn(2)
    return truth_seed, noise_seed


def truth(name: str, k: int) -> Design:
    """Instance k's hidden truth.

    Parameters
    ----------
    name : str
        A built-in participant.
    k : int
        The instance, 0 ≤ k ≤ `limits.MAX_INSTANCE`.

    Returns
    -------
    Design
        The shipped truth for k = 0, else a draw from the population prior with every ligament intact.
    """
    _check(name, k)
    if k == 0:
        return builtin.truth(name)
    materials = table2.sample_materials(1, seeds(name, k)[0])[0]
    injury = [design.INTACT_INJURY[n] for n in design.NAMES[design.N_MATERIAL :]]
    return design.from_action(np.r_[materials, injury])


def instance_key(name: str, k: int) -> str:
    """16 hex digits naming what instance k ≥ 1 is made from (its cache folder's key).

    Parameters
    ----------
    name : str
        A built-in participant: its high-fidelity model's source hash enters the key.
    k : int
        The instance, ≥ 1.

    Returns
    -------
    str
        A digest of the participant, k, `VERSION` and the source hash of the finer model its trials are
        simulated on.
    """
    from wrist_env.participants import synthetic  # the solver, on the first instance made or looked up

    text = json.dumps([name, int(k), VERSION, registry.model_source_hash(name, synthetic.HIGH_FIDELITY_BUILD)])
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _folder(name: str, k: int) -> Path:
    return cache.cache_dir() / "instances" / f"{name}-{k}-{instance_key(name, k)}"


def _load(folder: Path, name: str, k: int) -> Instance:
    record = read_json(folder / "instance.json", "instance record")["trials"]
    trials = {
        t: replace(read_trial_csv(folder / f"{t}.csv", t, e["role"], n_frames=e["frames"]), load_n=e["load_n"])
        for t, e in record.items()
    }
    return Instance(name, k, Design.from_dict(read_json(folder / "truth.json", "instance truth")), trials)


def _make(folder: Path, name: str, k: int) -> None:
    from wrist_env.participants import synthetic

    drawn = truth(name, k)
    try:
        trials, record = synthetic.synthetic_trials(name, builtin.info(name).task, drawn, seeds(name, k)[1])
    except synthetic.TrialsRefused as e:
        raise synthetic.TrialsRefused(f"instance {k} of {name} cannot be made (use another instance): {e}") from e
    temporary = folder.with_name(f".{folder.name}.{os.getpid()}.tmp")
    shutil.rmtree(temporary, ignore_errors=True)
    temporary.mkdir(parents=True)
    write_json(temporary / "truth.json", drawn.as_dict())
    for t, trial in trials.items():
        write_trial_csv(trial, temporary / f"{t}.csv")
        record[t]["frames"] = int(trial.transforms.shape[1])
    write_json(
        temporary / "instance.json", {"participant": name, "instance": int(k), "version": VERSION, "trials": record}
    )
    os.replace(temporary, folder)


@functools.lru_cache(maxsize=64)
def instance(name: str, k: int = 0) -> Instance:
    """Instance k of a built-in participant: a calibration problem, its hidden truth and its trials.

    Instance 0 is the shipped truth and trials; instance k ≥ 1 draws its truth from the population prior
    and makes its trials from it, seeded from (participant, k) alone, so it is the same problem on every
    machine. It is made on first use and cached beside the models.

    Parameters
    ----------
    name : str
        A built-in participant (P1, P2, P3).
    k : int, default 0
        The instance, 0 ≤ k ≤ `limits.MAX_INSTANCE`.

    Returns
    -------
    Instance
        ``truth`` (the hidden `Design`) and ``trials`` (one "calibrate", one "validate"; each bone's poses
        of shape (n_frames, 4, 4), mm).

    Raises
    ------
    ParticipantError
        `name` is not a built-in participant, or k is not an integer in range.
    synthetic.TrialsRefused
        The drawn truth cannot make a trial (the message names the instance).

    Examples
    --------
    >>> from wrist_env.participants.instances import instance
    >>> problem = instance("P1", 2)
    >>> problem.trial("calibrate").pose("scaphoid").shape  # doctest: +SKIP
    """
    _check(name, k)
    if k == 0:
        return Instance(name, 0, builtin.truth(name), dict(builtin.trials(name)))
    folder = _folder(name, k)
    if not (folder / "instance.json").is_file():
        folder.parent.mkdir(parents=True, exist_ok=True)
        with cache.cache_lock(folder):
            if not (folder / "instance.json").is_file():
                _make(folder, name, k)
    return _load(folder, name, k)
