"""Saved dataclasses (`.npz` + `.json`): atomic, hashed, and a damaged pair is a clear error."""

import json
import shutil
import warnings
from dataclasses import dataclass, field

import numpy as np
import pytest

from wrist_env.errors import StoreError
from wrist_env.io import load_dataclass, save_dataclass


@dataclass(frozen=True)
class Thing:
    name: str
    values: np.ndarray
    offsets: np.ndarray
    report: dict = field(default_factory=dict)


def _saved(tmp_path):
    thing = Thing("x", np.arange(12.0).reshape(4, 3), np.array([0, 2, 4]), {"a": 1})
    save_dataclass(thing, tmp_path / "t")
    return tmp_path / "t"


def test_round_trip_and_nothing_temporary_is_left(tmp_path):
    path = _saved(tmp_path)
    back = load_dataclass(Thing, path)
    np.testing.assert_array_equal(back.values, np.arange(12.0).reshape(4, 3))
    assert back.report == {"a": 1} and back.name == "x"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.json", "t.npz"]
    assert len(json.loads(path.with_suffix(".json").read_text())["npz_sha256"]) == 64


def _truncate(p):
    p.write_bytes(p.read_bytes()[: len(p.read_bytes()) // 2])


def _tamper(p):  # a well-formed .npz with other values, the .json left as it was
    with np.load(p) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["values"] = arrays["values"] * np.nan
    np.savez_compressed(p, **arrays)


DAMAGE = {
    "npz truncated": (".npz", _truncate),
    "npz zero bytes": (".npz", lambda p: p.write_bytes(b"")),
    "npz garbage": (".npz", lambda p: p.write_bytes(b"not a zip file at all")),
    "npz values changed": (".npz", _tamper),
    "npz missing": (".npz", lambda p: p.unlink()),
    "json truncated": (".json", _truncate),
    "json garbage": (".json", lambda p: p.write_bytes(b"\x00\xff{")),
    "json another class": (".json", lambda p: p.write_text(p.read_text().replace('"Thing"', '"Other"'))),
}


@pytest.mark.parametrize("case", sorted(DAMAGE))
def test_a_damaged_pair_is_a_store_error_naming_the_file(tmp_path, case):
    path = _saved(tmp_path)
    suffix, damage = DAMAGE[case]
    damage(path.with_suffix(suffix))
    with pytest.raises(StoreError) as err:
        load_dataclass(Thing, path)
    assert str(path) in str(err.value), err.value


def test_a_missing_field_is_named(tmp_path):
    path = _saved(tmp_path)

    @dataclass(frozen=True)
    class Thing2:  # noqa: D401 - same class name, one more field
        name: str
        values: np.ndarray
        offsets: np.ndarray
        extra: np.ndarray

    Thing2.__name__ = "Thing"
    with pytest.raises(StoreError, match="extra"):
        load_dataclass(Thing2, path)


def test_the_registry_rebuilds_a_damaged_cached_model_and_says_which(built, model_cache, tmp_path, monkeypatch):
    """A damaged cache entry is rebuilt (with a warning naming it), not loaded and not a crash; an entry
    of another participant or build under this entry's name is rebuilt too (no shipped model here: see
    tests/participants/test_registry.py for those)."""
    from wrist_env.participants import builtin, registry

    model = built("P1")
    monkeypatch.setenv("WRIST_ENV_CACHE", str(tmp_path))
    monkeypatch.setattr(builtin, "shipped_source_hash", lambda name: None)
    entry = tmp_path / f"P1-{model.source_hash}"
    rebuilt = []

    def fake_build(name, bones, params, **_):
        rebuilt.append(name)
        return model

    monkeypatch.setattr("wrist_env.builder.pipeline.build_model", fake_build)
    model.save(entry)
    assert registry.load_model("P1") is not model and not rebuilt  # read back from the cache
    entry.with_suffix(".npz").write_bytes(b"")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert registry.load_model("P1") is model
    assert rebuilt == ["P1"] and any(str(entry) in str(w.message) for w in caught)
    shutil.copy(entry.with_suffix(".json"), tmp_path / "keep.json")
    header = json.loads(entry.with_suffix(".json").read_text())
    header["fields"]["name"] = "P2"
    entry.with_suffix(".json").write_text(json.dumps(header))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        registry.load_model("P1")
    assert rebuilt == ["P1", "P1"] and any("'P2'" in str(w.message) for w in caught)


def _fifo(path):
    import os

    os.mkfifo(path)


SPECIAL = {
    "a link to /dev/zero": lambda p: p.symlink_to("/dev/zero"),  # endless: a read never ends
    "a FIFO": _fifo,  # no writer: opening it waits forever
}


@pytest.mark.timeout(30)
@pytest.mark.parametrize("suffix", [".json", ".npz"])
@pytest.mark.parametrize("special", sorted(SPECIAL))
def test_a_cache_file_that_is_not_a_regular_file_is_refused_not_read(tmp_path, special, suffix):
    """A cached model's file linked to a device (or a FIFO) made loading hang: it is named instead."""
    path = _saved(tmp_path)
    path.with_suffix(suffix).unlink()
    SPECIAL[special](path.with_suffix(suffix))
    with pytest.raises(StoreError, match="not a regular file") as err:
        load_dataclass(Thing, path)
    assert str(path.with_suffix(suffix)) in str(err.value) and "delete it to rebuild" in str(err.value)


@pytest.mark.timeout(30)
@pytest.mark.parametrize("special", sorted(SPECIAL))
def test_read_json_refuses_what_is_not_a_regular_file(tmp_path, special):
    from wrist_env.io import read_json

    path = tmp_path / "study.json"
    SPECIAL[special](path)
    with pytest.raises(StoreError, match=r"study.json: this manifest is a (character device|FIFO).*; restore it"):
        read_json(path, "manifest", "restore it")


@pytest.mark.timeout(30)
def test_a_model_whose_cached_json_is_a_device_is_refused(tmp_path):
    """`Model.load` (the registry's cache, `cache.cache_dir()`) reads through `load_dataclass`."""
    from wrist_env.model import Model

    (tmp_path / "P1-abc.json").symlink_to("/dev/zero")
    with pytest.raises(StoreError, match=r"P1-abc.json: this file is a character device"):
        Model.load(tmp_path / "P1-abc")
