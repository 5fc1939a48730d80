"""A Monte Carlo study's log on disk: its run store (`<out>/runs/*.parquet`, rows `sampler.SCHEMA`,
each part recording the settings it was made with and its participant's model and trials:
`wrist_env.runs.provenance`) and its manifest (`<out>/study.json`); reading the logged runs back,
refusing other settings or models (`check_settings` before a resume, `check_log` before a report), and
moving damaged or stray parts aside."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from wrist_env.errors import StoreError
from wrist_env.io import read_json, write_json
from wrist_env.montecarlo import sampler
from wrist_env.montecarlo.config import StudyConfig, StudyError
from wrist_env.runs import provenance
from wrist_env.runs.store import RunStore

MANIFEST = "study.json"
RUNS = "runs"
RERUN = "rerun the montecarlo command (same arguments) to simulate its runs again"


def runs_log(out: str | Path) -> RunStore:
    """The study's run store (parts in `<out>/runs`)."""
    return RunStore(Path(out), parts=RUNS)


def part_name(participant: str, ids: tuple[int, ...]) -> str:
    return f"{participant}-{ids[0]:07d}-{ids[-1] + 1:07d}"


SETTINGS = b"wrist_env.study"
"""The Parquet metadata key under which every part records the settings it was made with (`StudyConfig.key`)."""


def with_settings(table: pa.Table, config: StudyConfig, made_from: dict) -> pa.Table:
    """A chunk's rows with the study's settings and its participant's provenance (`provenance.of_participant`)
    in their metadata (so a part says what made it)."""
    table = table.replace_schema_metadata({SETTINGS: json.dumps(config.key(), sort_keys=True)})
    return provenance.with_provenance(table, made_from)


def part_settings(store: RunStore, name: str) -> dict | None:
    """The settings a part was made with (None: written before parts recorded them); StoreError if
    the part cannot be read."""
    return provenance.read_metadata(store.part_path(name), SETTINGS, RERUN)


def part_participant(name: str) -> str:
    """The participant a part's name (`part_name`) says it holds."""
    return name.rsplit("-", 2)[0]


def _differences(old: dict, key: dict) -> str:
    old, key = _settings(old), _settings(key)
    return ", ".join(f"{k} {old[k]!r} (asked {key[k]!r})" for k in sorted(key) if old[k] != key[k])


def check_settings(out: str | Path, config: StudyConfig, made_from: Callable[[str], dict] | None = None) -> None:
    """StudyError if a logged part was made under other settings than `config`'s, or on another model or
    trials than `made_from(participant)` gives (`provenance.of_participant`, where given: called only for
    participants with logged parts), or if neither its parts nor `study.json` say what they were made with
    (damaged parts are left to `repair`)."""
    out, key = Path(out), config.key()
    store, unrecorded = runs_log(out), []
    for name in store.part_names():
        try:
            settings = part_settings(store, name)
        except StoreError:
            continue
        if settings is None:
            unrecorded.append(name)
        elif _settings(settings) != _settings(key):
            raise StudyError(
                f"{store.part_path(name)}: its runs were made with other settings ({_differences(settings, key)}); "
                "use another --out or the same settings"
            )
    if unrecorded and not (out / MANIFEST).is_file():
        raise StudyError(
            f"{out}: {len(unrecorded)} parts (first {unrecorded[0]}.parquet) do not record their settings and there "
            f"is no {MANIFEST} to say them; restore it, or use another --out"
        )
    for name in store.part_names():
        if made_from is None:
            break
        try:
            recorded = provenance.read_provenance(store.part_path(name), RERUN)
        except StoreError:
            continue
        changed = provenance.differences(recorded, made_from(part_participant(name)))
        if changed:
            raise StudyError(
                f"{store.part_path(name)}: its runs were made on another model or trials of "
                f"{part_participant(name)} ({changed}); use another --out to run the study on today's"
            )


def check_log(out: str | Path, config: StudyConfig) -> None:
    """Before a report: StudyError naming the part unless every part was made with `config`'s settings
    (`study.json`'s), holds the runs its name says, once, and agrees with the other parts of its
    participant on the model and trials (a part copied from another study, a `study.json` edited, a
    model changed between a kill and a resume)."""
    check_settings(out, config)
    store = runs_log(out)
    stray = _stray_parts(store)
    if stray:
        name, why = stray[0]
        raise StudyError(f"{store.part_path(name)}: {why.split(';')[0]}; {RERUN} (it moves such parts aside)")
    first: dict[str, tuple[str, dict | None]] = {}
    for name in store.part_names():
        made_from = provenance.read_provenance(store.part_path(name), RERUN)
        p = part_participant(name)
        seen, recorded = first.setdefault(p, (name, made_from))
        if recorded != made_from:
            if recorded is None or made_from is None:
                changed = "one of the two does not record its model (made by an older wrist-env)"
            else:
                changed = provenance.differences(made_from, recorded, against=f"{seen}.parquet")
            raise StudyError(
                f"{store.part_path(name)}: made on another model or trials of {p} than {seen}.parquet ({changed}); "
                "a study's runs must share one model: move the odd parts away, or rerun the study in another --out"
            )


def repair(out: str | Path) -> int:
    """Before a run: remove killed writers' temporary files and move to `<out>/damaged/` every damaged
    part and every part that is not where the study writes it (a copy, or runs logged twice); their
    runs are then missing, and simulated again. Returns the parts moved."""
    store = runs_log(out)
    store.clean(min_age_s=0.0)  # the caller holds the store lock: no live writer
    damaged = [
        (n, "damaged Parquet part, its runs are simulated again") for n, _ in store.damaged_parts(sampler.SCHEMA)
    ]
    return sum(store.quarantine(store.part_path(n), why) is not None for n, why in damaged + _stray_parts(store))


def _stray_parts(store: RunStore) -> list[tuple[str, str]]:
    """(name, reason) of the readable parts whose runs are not the ones their name says (a copy under
    another name) or were logged by an earlier part."""
    seen: dict[str, set[int]] = {}
    out = []
    for name in store.part_names():
        try:
            cols = store.read_part(name, columns=["participant", "sample_id"]).to_pydict()
        except StoreError:
            continue  # damaged: moved by `repair`
        ids, participants = tuple(cols["sample_id"]), set(cols["participant"])
        p = next(iter(participants)) if len(participants) == 1 else None
        if p is None or not ids or ids != tuple(range(ids[0], ids[0] + len(ids))) or part_name(p, ids) != name:
            out.append((name, "its runs are not the ones its name says (a copy?); moved aside, not used"))
        elif seen.setdefault(p, set()) & set(ids):
            out.append((name, "repeats runs an earlier part logged; moved aside, not used"))
        else:
            seen[p].update(ids)
    return out


def read_runs(out: str | Path, columns: list[str] | None = None) -> pa.Table | None:
    """Every logged run of the study in `out`, sorted by (participant, sample_id); None if empty.

    Parameters
    ----------
    out : str or Path
        The study's folder.
    columns : list of str, optional
        The columns to read (default: all of `sampler.SCHEMA`). Without both "participant" and
        "sample_id" the table is returned in the parts' order, unsorted and unchecked for duplicates.

    Returns
    -------
    pyarrow.Table or None
        One row per run (n_runs rows; the columns of `sampler.SCHEMA`: per-frame outputs as lists of
        n_frames), or None if nothing is logged.

    Raises
    ------
    StudyError
        A run is logged twice (the message names both parts).
    StoreError
        A damaged part (the message names it).
    """
    store = runs_log(out)
    names = store.part_names()
    if not names:
        return None
    tables = [store.read_part(n, sampler.SCHEMA, columns, RERUN) for n in names]
    table = pa.concat_tables(tables)
    keys = ["participant", "sample_id"]
    if columns is not None and not set(keys) <= set(columns):
        return table
    order = pc.sort_indices(table, sort_keys=[(k, "ascending") for k in keys])
    table = table.take(order)
    source = np.repeat(np.arange(len(names)), [t.num_rows for t in tables])[order.to_numpy()]
    p, s = table["participant"].to_numpy(zero_copy_only=False), table["sample_id"].to_numpy()
    dup = (p[1:] == p[:-1]) & (s[1:] == s[:-1])
    if dup.any():
        i = int(np.flatnonzero(dup)[0])
        first, second = sorted((names[source[i]], names[source[i + 1]]))
        raise StudyError(
            f"{store.part_path(second)}: run {p[i]} #{s[i]} is logged twice (also in {first}.parquet); "
            "rerun the montecarlo command (same arguments) to move the copy aside"
        )
    return table


def _settings(key: dict) -> dict:
    """A study key's fields with the load direction filled in (a key leaves out the axial default)."""
    fields = set(StudyConfig(("-",), 1).key()) | {"load_direction"}
    return {k: key.get(k, "axial" if k == "load_direction" else None) for k in fields}


def _manifest(out: Path, config: StudyConfig) -> None:
    path = out / MANIFEST
    key = config.key()
    participants = list(config.participants)
    if path.is_file():
        old = read_json(path, "study manifest", "it records the study's settings: restore it, or use another --out")
        if _settings(old) != _settings(key):
            raise StudyError(
                f"{out} holds another study ({_differences(old, key)}); use another --out or the same settings"
            )
        participants = list(old.get("participants", [])) + [
            p for p in participants if p not in old.get("participants", [])
        ]
        if participants == old.get("participants"):
            return
    write_json(path, {**key, "participants": participants})


def read_manifest(out: str | Path) -> dict:
    path = Path(out) / MANIFEST
    if not path.is_file():
        raise StudyError(f"{out} holds no Monte Carlo study (no {MANIFEST})")
    return read_json(path, "study manifest", "it records the study's settings: restore it, or use another --out")
