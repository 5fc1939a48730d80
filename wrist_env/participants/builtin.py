"""Built-in participants P1–P3 (preprint Table 1), synthetic and said to be.

No 4DCT ships, so each built-in participant is the anatomy template under a
smooth participant-specific warp and isotropic scale, with hidden
ground-truth ligament properties drawn from Table 2's distributions (fixed
seed). `experiments/authoring/make_participants.py` writes the data files under
`participants/data/<name>/` (`participant.json`, `truth.json`);
`experiments/authoring/make_trials.py` their trials (`trials.json`, `trials/*.csv`).
`source` gives one as a `ParticipantSource`, to write as a participant folder.
"""

from __future__ import annotations

import functools
import importlib.resources
import json
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from wrist_env.anatomy.template import BoneSurface, load_template
from wrist_env.builder.params import BuildParams
from wrist_env.builder.warp import Warp
from wrist_env.design import Design
from wrist_env.errors import ParticipantError
from wrist_env.model import SUPPLIED
from wrist_env.participants import BUILTIN
from wrist_env.participants.folder import ParticipantSource
from wrist_env.trial import read_trial_csv

if TYPE_CHECKING:
    from wrist_env.participants.folder import ParticipantSource

TRACKING_NOISE_MM, TRACKING_NOISE_DEG = 0.2, 0.5
"""RMS of the synthetic trials' 4DCT tracking noise: a rigid perturbation of each bone per frame."""


@dataclass(frozen=True)
class BuiltinInfo:
    """Table 1 facts and the synthetic warp of one built-in participant."""

    name: str
    sex: str
    age: int
    facet_type: str
    task: str
    warp: dict
    truth_seed: int


ULNAR_VARIANCE_MM = 0.26
"""The built-in participants' ulnar variance (mm, + ulna plus): the adult mean, Yoshioka et al. 2007
(range −4.6 to +3.7 mm). Their bones are the template's under a warp, and myo-sim's wrist is ulna minus
(about −3 mm by `anatomy.ulnar_variance`'s corner rule): the build seats the ulna at this
(`registry.build_params`, `BuildParams.ulnar_variance_mm`)."""


def _data(name: str, file: str) -> dict:
    if name not in BUILTIN:
        raise ParticipantError(f"unknown built-in participant {name!r}; the built-in ones are {list(BUILTIN)}")
    path = importlib.resources.files("wrist_env.participants") / "data" / name / file
    return json.loads(path.read_text())


def info(name: str) -> BuiltinInfo:
    """Table 1 facts and warp parameters of a built-in participant."""
    return BuiltinInfo(**_data(name, "participant.json"))


def truth(name: str) -> Design:
    """The hidden ground-truth ligament design of a built-in participant."""
    return Design.from_dict(_data(name, "truth.json"))


@functools.lru_cache(maxsize=len(BUILTIN))
def trials(name: str) -> dict:
    """The participant's synthetic trials {name: Trial} (see `experiments/authoring/make_trials.py`)."""

    meta = _data(name, "trials.json")
    root = importlib.resources.files("wrist_env.participants") / "data" / name
    return {
        t: replace(
            read_trial_csv(root / entry["file"], t, entry["role"], n_frames=meta["frames"]), load_n=entry["load_n"]
        )
        for t, entry in meta["trials"].items()
    }


@functools.lru_cache(maxsize=4 * len(BUILTIN))
def bones(name: str, fossa_sweep_deg: tuple = (0.0, 0.0), distal_row: bool = False) -> dict:
    """The participant's bones: the template (variant as in `load_template`) under its warp
    (name -> BoneSurface, RCS mm)."""
    warp = Warp.from_dict(info(name).warp)
    out = {}
    for bone, surface in load_template(tuple(fossa_sweep_deg), distal_row).bones.items():
        v = warp.apply(surface.vertices)
        v.setflags(write=False)
        out[bone] = BoneSurface(bone, v, surface.faces, surface.solid, surface.part)
    return out


SHIPPED_MODEL = "model"
"""The built model shipped beside a built-in participant's data (`model.npz` + `model.json`, written by
`python experiments/authoring/ship_models.py`, a step of `experiments/regenerate.py`); `registry.load_model`
uses it when its source hash is the one it would build, and builds otherwise (a changed builder, template or platform)."""


def shipped_model_path(name: str) -> Path | None:
    """The base path of the model shipped with built-in participant `name`, or None if none ships."""
    if name not in BUILTIN:
        return None
    path = Path(str(importlib.resources.files("wrist_env.participants") / "data" / name / SHIPPED_MODEL))
    return path if path.with_suffix(".json").is_file() else None


def shipped_source_hash(name: str) -> str | None:
    """The source hash of the shipped model of `name` (read from its JSON), or None."""
    path = shipped_model_path(name)
    if path is None:
        return None
    try:
        return json.loads(path.with_suffix(".json").read_text())["fields"]["source_hash"]
    except (OSError, ValueError, KeyError, TypeError):
        return None


def source(name: str, fossa_sweep_deg: tuple | None = None) -> ParticipantSource:
    """The participant as a `folder.ParticipantSource`: its five principal bones (the radius fossae swept
    as in `load_template`; default: `BuildParams()`'s), its trials and Table 1 facts, a right wrist.

    `folder.write_participant_folder` writes it as a folder that loads back; its radius keeps the open
    shaft beside the closed articular solid, and its ulna is closed at the cut (`anatomy.template.closed`);
    the radial column is not a folder's: it comes with the capitate (`model.SUPPLIED`).
    """

    sweep = BuildParams().fossa_sweep_deg if fossa_sweep_deg is None else fossa_sweep_deg
    facts = info(name)
    meta = {
        "side": "right",
        "sex": facts.sex,
        "age": facts.age,
        "facet_type": facts.facet_type,
        "task": facts.task,
        "frames": _data(name, "trials.json")["frames"],
    }
    surfaces = bones(name, tuple(float(a) for a in sweep), False)
    root = importlib.resources.files("wrist_env.participants") / "data" / name
    return ParticipantSource(
        name, meta, {b: (surfaces[b].vertices, surfaces[b].faces) for b in SUPPLIED}, trials(name), Path(str(root))
    )


def tracking_noise(transforms, centroid, rng):
    """Poses (n, 4, 4) perturbed by a random rigid motion about the moved centroid (mm) per frame:
    `TRACKING_NOISE_MM` and `TRACKING_NOISE_DEG` RMS (isotropic), drawn from `rng`."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    n = len(transforms)
    turn = Rotation.from_rotvec(rng.normal(0.0, np.radians(TRACKING_NOISE_DEG) / np.sqrt(3), (n, 3))).as_matrix()
    shift = rng.normal(0.0, TRACKING_NOISE_MM / np.sqrt(3), (n, 3))
    out = np.array(transforms, dtype=np.float64, copy=True)
    moved = np.einsum("fij,j->fi", out[:, :3, :3], centroid) + out[:, :3, 3]
    out[:, :3, :3] = turn @ out[:, :3, :3]
    out[:, :3, 3] = np.einsum("fij,fj->fi", turn, out[:, :3, 3] - moved) + moved + shift
    return out
