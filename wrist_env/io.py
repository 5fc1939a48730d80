"""Save and load frozen dataclasses of arrays as `.npz` + `.json` (never pickle).

Array fields (and tuples of arrays) go to the `.npz`; everything else must be
JSON-able and goes to the `.json`, with the class name and a format version.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np

FORMAT_VERSION = 1


def save_dataclass(obj, path) -> None:
    """Write `path.npz` and `path.json` for the frozen dataclass `obj`."""
    path = Path(path)
    arrays, meta = {}, {}
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if isinstance(value, np.ndarray):
            arrays[f.name] = value
        else:
            meta[f.name] = value
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path.with_suffix(".npz"), **arrays)
    header = {"class": type(obj).__name__, "format": FORMAT_VERSION, "fields": meta}
    path.with_suffix(".json").write_text(json.dumps(header, indent=1, default=_jsonable))


def load_dataclass(cls, path):
    """Read an instance of `cls` written by `save_dataclass`."""
    path = Path(path)
    header = json.loads(path.with_suffix(".json").read_text())
    if header.get("class") != cls.__name__ or header.get("format") != FORMAT_VERSION:
        raise ValueError(f"{path.with_suffix('.json')} holds {header.get('class')} v{header.get('format')}, "
                         f"not {cls.__name__} v{FORMAT_VERSION}")
    with np.load(path.with_suffix(".npz"), allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    kwargs = {**header["fields"], **arrays}
    for f in dataclasses.fields(cls):
        if isinstance(kwargs.get(f.name), list) and str(f.type).startswith("tuple"):
            kwargs[f.name] = tuple(kwargs[f.name])
    return cls(**kwargs)


def _jsonable(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, tuple):
        return list(value)
    raise TypeError(f"{type(value).__name__} is not JSON-able")
