"""What a log was made from, recorded in every log and checked wherever a log is read back.

A study's or a benchmark cell's runs mean something only on the model and the trials that made them:
edit a folder participant's mesh or calibrate trial, and a log made before is another experiment. Every
log therefore records its participant's provenance (`of_participant`): the model's `Model.source_hash`
(the hash of its bones and build parameters) and each trial's `trial_digest` (its name, role, bones,
transforms and loads). A resume compares it with today's and moves aside or refuses what differs; a
report or a leaderboard refuses logs of one participant that disagree among themselves. Parquet parts
keep it in their schema metadata under `KEY` (`with_provenance`, `read_provenance`), records under `FIELD`.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from wrist_env.errors import StoreError
from wrist_env.trial import Trial

KEY = b"wrist_env.provenance"
"""The Parquet schema-metadata key of a part's provenance."""
FIELD = "provenance"
"""The field of a JSON record (a cell summary) holding its provenance."""


def trial_digest(trial: Trial) -> str:
    """The SHA-256 (hex) of what a trial is: its name, role, bones, transforms (float64, C order) and loads."""
    h = hashlib.sha256()
    h.update(json.dumps([trial.name, trial.role, list(trial.bones)]).encode())
    h.update(np.ascontiguousarray(trial.transforms, dtype=np.float64).tobytes())
    if trial.load_n is not None:
        h.update(b"load_n")
        h.update(np.ascontiguousarray(trial.load_n, dtype=np.float64).tobytes())
    return h.hexdigest()


def of_participant(name: str, instance: int = 0) -> dict:
    """{"model": the participant's `Model.source_hash`, "trials": {trial name: `trial_digest`}} today
    (loads the model: from the cache, or built on a miss). For a problem instance k ≥ 1
    (`participants.instances`) the trials are the instance's and "instance": k is added, so a log made
    on one instance differs from another's (instance 0 records no "instance", as logs made before
    instances do)."""
    from wrist_env.participants import instances, registry  # the registry builds on the solver

    trials = registry.trials(name) if instance == 0 else instances.instance(name, instance).trials
    out = {
        "model": registry.load_model(name).source_hash,
        "trials": {t: trial_digest(trials[t]) for t in sorted(trials)},
    }
    return out if instance == 0 else {**out, "instance": int(instance)}


def differences(recorded: dict | None, current: dict, against: str = "now") -> str:
    """What differs between a recorded provenance and `current` (`against` names it), in words ("" if
    nothing does)."""
    if not isinstance(recorded, dict):
        return "it does not record the model and trials it was made with (made by an older wrist-env)"
    out = []
    if recorded.get("instance", 0) != current.get("instance", 0):
        out.append(f"instance {recorded.get('instance', 0)} ({against} {current.get('instance', 0)})")
    if recorded.get("model") != current.get("model"):
        out.append(f"model {str(recorded.get('model'))[:12]}… ({against} {str(current.get('model'))[:12]}…)")
    old, new = recorded.get("trials") or {}, current.get("trials") or {}
    changed = sorted(t for t in set(old) | set(new) if old.get(t) != new.get(t))
    if changed:
        out.append(f"trials {', '.join(changed)} changed")
    return ", ".join(out)


def with_provenance(table: pa.Table, provenance: dict) -> pa.Table:
    """`table` with `provenance` added to its schema metadata (other metadata kept)."""
    metadata = dict(table.schema.metadata or {})
    metadata[KEY] = json.dumps(provenance, sort_keys=True)
    return table.replace_schema_metadata(metadata)


def read_metadata(path: str | Path, key: bytes, advice: str = "") -> dict | None:
    """The JSON a Parquet file keeps under schema-metadata `key` (None if it has none); `StoreError`
    naming the file if it cannot be read."""
    try:
        raw = (pq.read_schema(path).metadata or {}).get(key)
        return None if raw is None else json.loads(raw)
    except (OSError, pa.ArrowException, ValueError) as e:
        raise StoreError(
            f"{path}: damaged Parquet part ({type(e).__name__}){f'; {advice}' if advice else ''}"
        ) from None


def read_provenance(path: str | Path, advice: str = "") -> dict | None:
    """A part's recorded provenance (None: made before parts recorded it)."""
    return read_metadata(path, KEY, advice)
