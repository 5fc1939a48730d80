"""Participants by name: the built-in P1–P3 and user folders, and their cached models.

Models are cached as `.npz` + `.json` under `$WRIST_ENV_CACHE` (default
`~/.cache/wrist_env`), keyed by a hash of the bones, the build parameters,
the annotations and the builder version.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from wrist_env.anatomy.template import BoneSurface, carry_parts, load_template
from wrist_env.builder.digest import source_hash
from wrist_env.builder.params import BuildParams
from wrist_env.errors import BuildError, ParticipantError, StoreError
from wrist_env.model import BONES, OPTIONAL_BONES, SUPPLIED, Model
from wrist_env.participants import builtin
from wrist_env.participants import folder as folder_module  # by module: tests count its reads
from wrist_env.participants.bone_mesh import solid_mask
from wrist_env.participants.cache import cache_dir, cache_lock, cached, check_cache

if TYPE_CHECKING:
    from wrist_env.solver.settings import SolverSettings
    from wrist_env.trial import Trial

_FOLDERS: dict[str, Path] = {}
_SOURCES: dict = {}  # name -> the ParticipantSource read once by add_folder


def participants() -> tuple[str, ...]:
    """Names of all known participants.

    Returns
    -------
    tuple of str
        The built-in ones first, then the registered folders'.
    """
    return builtin.BUILTIN + tuple(n for n in _FOLDERS if n not in builtin.BUILTIN)


def require(*names: str) -> None:
    """Check that every name is a known participant.

    Parameters
    ----------
    *names : str
        The names to check.

    Raises
    ------
    ParticipantError
        A name is not a known participant (the message lists the known ones).
    """
    unknown = [n for n in names if n not in participants()]
    if unknown:
        raise ParticipantError(
            f"unknown participant{'s' if len(unknown) > 1 else ''} "
            f"{unknown if len(unknown) > 1 else repr(unknown[0])}; known: {list(participants())}"
        )


def folder(name: str) -> Path:
    """The folder a registered participant was read from.

    Parameters
    ----------
    name : str
        A participant registered from a folder (`add_folder`).

    Returns
    -------
    Path
        Its folder, as given to `add_folder`.

    Raises
    ------
    ParticipantError
        An unknown participant, or a built-in one.
    """
    require(name)
    if name not in _FOLDERS:
        raise ParticipantError(f"participant {name!r} is built in, not read from a folder")
    return _FOLDERS[name]


def add_folder(folder: str | Path) -> str:
    """Validate a participant folder and make it known by its name.

    The folder is read and checked once, here: edit its files, then add it again.

    Parameters
    ----------
    folder : str or Path
        The participant folder (its `participant.toml`, bones and trials).

    Returns
    -------
    str
        The participant's name.
    """

    source = folder_module.load_participant_folder(folder)
    if source.name in builtin.BUILTIN:
        raise ParticipantError(
            f"{Path(folder) / 'participant.toml'}: name {source.name!r} is taken by a built-in participant"
        )
    if source.name in _FOLDERS and _FOLDERS[source.name].resolve() != folder_module.resolved(folder):
        raise ParticipantError(
            f"{Path(folder) / 'participant.toml'}: name {source.name!r} is taken by the folder {_FOLDERS[source.name]}"
        )
    _FOLDERS[source.name] = Path(folder)
    _SOURCES[source.name] = source
    return source.name


def ensure_folder(folder: str | Path) -> str:
    """`add_folder` unless this folder is registered already.

    For a worker or a runner given the folders a caller registered: each is read once, not again.

    Parameters
    ----------
    folder : str or Path
        A participant folder, registered in this process or not.

    Returns
    -------
    str
        The participant's name.
    """
    here = folder_module.resolved(folder)  # ParticipantError for a null byte or a symlink loop
    for name, path in _FOLDERS.items():
        if path.resolve() == here:
            return name
    return add_folder(folder)


def bones(name: str, params: BuildParams | None = None) -> dict:
    """The participant's bones for the anatomy variant of the build parameters.

    Parameters
    ----------
    name : str
        A built-in participant or a registered folder's.
    params : BuildParams, optional
        The build parameters whose anatomy variant is given (default `BuildParams()`).

    Returns
    -------
    dict of str to BoneSurface
        Bone name → surface, RCS mm, neutral pose.
    """
    params = params or BuildParams()
    if name in builtin.BUILTIN:
        return builtin.bones(name, *params.anatomy)
    require(name)

    source = _SOURCES[name]
    surfaces = {b: BoneSurface(b, v, f, solid_mask(v, f)) for b, (v, f) in source.bones.items()}
    principal = {b: surfaces[b] for b in SUPPLIED}
    given = {b: surfaces[b] for b in OPTIONAL_BONES if b in surfaces}
    return carry_parts(principal, load_template(), params.distal_row, given)


def build_params(name: str, params: BuildParams | None = None) -> BuildParams:
    """The build parameters with the participant's ulnar variance where they leave it None.

    Parameters
    ----------
    name : str
        A built-in participant or a registered folder's (whose participant.toml may state its ulnar variance).
    params : BuildParams, optional
        The build parameters (default `BuildParams()`); a value of their ulnar variance wins.

    Returns
    -------
    BuildParams
        `params` with a built-in's `builtin.ULNAR_VARIANCE_MM`, or a folder's participant.toml's
        `ulnar_variance_mm` if it states one.
    """
    params = params or BuildParams()
    if params.ulnar_variance_mm is not None:
        return params
    if name in builtin.BUILTIN:
        return replace(params, ulnar_variance_mm=builtin.ULNAR_VARIANCE_MM)
    require(name)
    stated = _SOURCES[name].meta.get("ulnar_variance_mm")
    return params if stated is None else replace(params, ulnar_variance_mm=stated)


def trials(name: str) -> dict:
    """The participant's trials.

    Parameters
    ----------
    name : str
        A built-in participant or a registered folder's.

    Returns
    -------
    dict of str to Trial
        Trial name → Trial; at least one has role "calibrate".
    """
    if name in builtin.BUILTIN:
        return builtin.trials(name)
    require(name)
    return _SOURCES[name].trials


def trial(name: str, role: str) -> Trial:
    """The participant's first trial with a role.

    Parameters
    ----------
    name : str
        A built-in participant or a registered folder's.
    role : str
        "calibrate" or "validate".

    Returns
    -------
    Trial
        Its first trial with `role`.

    Raises
    ------
    ParticipantError
        It has no trial with `role` (the message lists its trials' roles).
    """
    found = [t for t in trials(name).values() if t.role == role]
    if not found:
        raise ParticipantError(
            f"participant {name!r} has no trial with role {role!r}; its trials: "
            f"{ {k: t.role for k, t in trials(name).items()} }"
        )
    return found[0]


def model_source_hash(name: str, params: BuildParams | None = None) -> str:
    """The source hash of the model `load_model(name, params)` gives (`builder.digest.source_hash` of its bones
    and build parameters), without building or loading it."""
    params = build_params(name, params)
    return source_hash(name, bones(name, params), params)


def load_model(name: str, params: BuildParams | None = None, *, cache: bool = True) -> Model:
    """The participant's model, built on first use and cached by the hash of its inputs.

    A built-in participant's shipped model is used when its hash is that of the inputs
    (`builtin.SHIPPED_MODEL`).

    Parameters
    ----------
    name : str
        A built-in participant (P1–P3) or a registered folder's (`add_folder`).
    params : BuildParams, optional
        The build parameters (default `BuildParams()`). A participant folder's stated ulnar variance applies
        where they leave it None (`build_params`).
    cache : bool, default True
        Read and write the cache (`cache_dir`); False builds afresh and caches nothing.

    Returns
    -------
    Model
        The built (or cached, or shipped) model.
    """
    params = build_params(name, params)
    b = bones(name, params)
    digest = source_hash(name, b, params)
    path = cache_dir() / f"{name}-{digest}"
    model = cached(path, name, digest) if cache else None
    if model is not None:
        return model
    if cache and builtin.shipped_source_hash(name) == digest:
        try:
            return Model.load(builtin.shipped_model_path(name))
        except StoreError as e:
            warnings.warn(f"building instead of reading a damaged shipped model: {e}", stacklevel=2)
    if not cache:
        return _build(name, b, params, digest)
    check_cache(path)  # before a build of minutes, not after
    with cache_lock(path):  # another process building this model: wait for it, then load what it saved
        model = cached(path, name, digest, quiet=True)
        if model is None:
            model = _build(name, b, params, digest)
            try:
                model.save(path)
            except OSError as e:  # the build is not lost: the model is used uncached
                warnings.warn(f"{path}: the built model could not be cached ({type(e).__name__}: {e})", stacklevel=2)
    return model


def _build(name: str, b: dict, params: BuildParams, digest: str) -> Model:
    from wrist_env.builder.pipeline import build_model  # the builder (scikit-learn, libigl) only on a cache miss

    try:
        return build_model(name, b, params, digest=digest)
    except BuildError as e:
        if name in _FOLDERS:  # name the folder's file
            raise BuildError(f"{_FOLDERS[name] / 'participant.toml'}: {e}") from e
        raise


def warm_solver(settings: SolverSettings | None = None) -> None:
    """Compile (or load from Numba's cache) the solver's entry point for `settings`, on built-in P1.

    What a study runs before its local worker processes start (`runs.executor(warm=...)`), so that each loads
    the compiled kernel instead of compiling it: P1 is shipped with the package, so nothing is built, and the
    kernel's types do not depend on the participant (`simulate.warm`).

    Parameters
    ----------
    settings : SolverSettings, optional
        The solver's settings (default ``SolverSettings()``).
    """
    from wrist_env.solver.simulate import warm  # loads Numba

    warm(load_model("P1"), settings)


__all__ = [
    "BONES",
    "add_folder",
    "ensure_folder",
    "bones",
    "build_params",
    "folder",
    "load_model",
    "participants",
    "require",
    "trial",
    "trials",
    "warm_solver",
]
