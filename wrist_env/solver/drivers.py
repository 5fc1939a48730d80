"""The capitate's drivers and the loads on the bodies: what a simulation is asked to do, frame by frame.

`experimental(model, transforms)` prescribes all 6 DOF of the capitate from a trial's 4×4 transforms
(`trial_driver` for a `Trial`); `loaded(model, rotations, load_n)` prescribes its rotations and leaves its
translations free under a compressive load (N) on lines of action (`Loads`: along the radius' axis,
`AXIAL`, or the tendons where they enter the hand: `settings.LOAD_DIRECTIONS`); `idealized(model)` is the loaded
driver ramping from maximum flexion to maximum extension (deg) about the RCS z axis; `static` holds it
at neutral. `for_motion` maps a motion's name (`motions.DRIVEN_MOTIONS`) to its driver: the one owner of that
map. Poses in the RCS, mm.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from wrist_env.anatomy.tendons import model_lines
from wrist_env.errors import InputError
from wrist_env.limits import MAX_FRAMES, MAX_SWEEP_DEG, check_float, check_int
from wrist_env.model import CAPITATE, Model
from wrist_env.motions import DRIVEN_MOTIONS, IDEALIZED, TRIAL_MOTIONS
from wrist_env.solver import arrays, step
from wrist_env.solver.settings import DEFAULT_LOADS, JIG, LOAD_DIRECTIONS

if TYPE_CHECKING:
    from wrist_env.trial import Trial

IDEALIZED_LOAD_N = 10.0  # compressive load that keeps the joint in contact (N)
AXIAL = (0.0, 1.0, 0.0)  # the load along the radius' long axis, proximal (RCS +y)


@dataclass(frozen=True)
class Driver:
    """Capitate targets per frame and the loads on the bodies.

    mode: arrays.EXPERIMENTAL (the capitate's 6 DOF prescribed) or arrays.LOADED (its rotations
    prescribed, its translations free under its loads); rotation (n_frames, 3, 3), com (n_frames, 3)
    mm; angle_deg (n_frames,) the wrist flexion angle of each frame (idealized) or NaN.
    Loads, as lines of action (`Loads`): load_n (n_frames,) the total tension, N, shared among the
    lines by `loads.share`; each line pulls its body at a point fixed in the body along a direction
    fixed in the RCS (the tendons run along the forearm).
    """

    mode: int
    rotation: np.ndarray
    com: np.ndarray
    angle_deg: np.ndarray
    load_n: np.ndarray
    loads: "Loads" = None

    def __post_init__(self):
        if self.loads is None:
            object.__setattr__(self, "loads", axial_load())

    @property
    def n_frames(self) -> int:
        return len(self.rotation)

    def load(self, frame: int | None = None) -> np.ndarray:
        """Tension of each line (N): (n_lines,) at `frame`, or (n_frames, n_lines)."""
        if frame is None:
            return np.ascontiguousarray(self.load_n[:, None] * self.loads.share)
        return self.load_n[frame] * self.loads.share

    def kernel_load(self, frame: int | None = None) -> step.Load:
        """The lines of action as the kernel takes them (`step.Load`), tensions as `load(frame)`."""
        lines = self.loads
        return step.Load(
            np.ascontiguousarray(lines.body, dtype=np.int64),
            np.ascontiguousarray(lines.point, dtype=np.float64),
            np.ascontiguousarray(lines.direction, dtype=np.float64),
            np.ascontiguousarray(self.load(frame), dtype=np.float64),
        )

    def resultant(self, frame: int) -> np.ndarray:
        """The loads' resultant force (3,) N, RCS, at `frame`."""
        return self.load(frame) @ self.loads.direction


@dataclass(frozen=True)
class Loads:
    """Lines of action: body (n,) index into `BONES`; point (n, 3) mm, where each pulls, in its body's
    neutral pose (RCS); direction (n, 3) unit pull, RCS; share (n,) of the total tension (sum 1);
    name: what they are (a `LOAD_DIRECTIONS` name or "custom")."""

    body: np.ndarray
    point: np.ndarray
    direction: np.ndarray
    share: np.ndarray
    name: str = "custom"


def axial_load(model: Model | None = None, direction: ArrayLike = AXIAL) -> Loads:
    """One line on the capitate's centre of mass along `direction` (default `AXIAL`)."""
    com = np.zeros(3) if model is None else model.com[CAPITATE]
    d = np.asarray(direction, dtype=np.float64)
    return Loads(
        np.array([CAPITATE]),
        com[None].copy(),
        (d / np.linalg.norm(d))[None],
        np.ones(1),
        "axial" if model else "custom",
    )


def experimental(
    model: Model, transforms: ArrayLike, load_n: ArrayLike = 0.0, direction: str | ArrayLike = DEFAULT_LOADS
) -> Driver:
    """Driver from the capitate's 4×4 transforms (n_frames, 4, 4), neutral → frame, RCS mm; the free
    bodies under `load_n` (N, total: a scalar or one per frame, e.g. a `Trial`'s) on the lines of
    `direction` (see `loads`; the capitate's lines do nothing: it is prescribed, the radial column's
    load it)."""
    T = np.asarray(transforms, dtype=np.float64)
    com0 = model.com[CAPITATE]
    rotation = np.ascontiguousarray(T[:, :3, :3])
    com = np.einsum("fij,j->fi", rotation, com0) + T[:, :3, 3]
    n = len(T)
    return Driver(
        arrays.EXPERIMENTAL,
        rotation,
        np.ascontiguousarray(com),
        np.full(n, np.nan),
        np.broadcast_to(np.asarray(load_n, dtype=np.float64), (n,)).copy(),
        loads(model, direction),
    )


def trial_driver(model: Model, trial: Trial, direction: str | ArrayLike = DEFAULT_LOADS) -> Driver:
    """The experimental driver of a `Trial`: its capitate's poses, the free bodies under its recorded
    total load per frame (`Trial.load_n`; none if it has none) on the lines of `direction`."""
    load_n = 0.0 if trial.load_n is None else trial.load_n
    return experimental(model, trial.pose("capitate"), load_n, direction)


def loaded(
    model: Model,
    rotations: ArrayLike,
    load_n: ArrayLike = IDEALIZED_LOAD_N,
    angle_deg: ArrayLike | None = None,
    direction: str | ArrayLike = DEFAULT_LOADS,
) -> Driver:
    """Capitate rotations (n_frames, 3, 3) prescribed, its translations free under a
    total load `load_n` (N; a scalar or one per frame) on the lines of `direction` (see `loads`)."""
    rotation = np.ascontiguousarray(np.asarray(rotations, dtype=np.float64))
    n = len(rotation)
    load = np.broadcast_to(np.asarray(load_n, dtype=np.float64), (n,)).copy()
    if not np.all(np.isfinite(load) & (load >= 0)):  # a NaN would reach the solver, a pull is not this load
        raise InputError(f"load_n must be finite and >= 0 N (a compressive load), but got {load_n!r}")
    com = np.tile(model.com[CAPITATE], (n, 1))
    angle = np.full(n, np.nan) if angle_deg is None else np.asarray(angle_deg, dtype=np.float64)
    return Driver(arrays.LOADED, rotation, com, angle, load, loads(model, direction))


def loads(model: Model, direction: str | ArrayLike) -> Loads:
    """The `Loads` of a `LOAD_DIRECTIONS` name, or one line on the capitate along a (3,) vector; a wrong
    name or shape, a non-finite or a zero vector is refused."""
    if isinstance(direction, str):
        if direction not in LOAD_DIRECTIONS:
            raise ValueError(f"load_direction must be one of {LOAD_DIRECTIONS} or a (3,) vector, but got {direction!r}")
        if direction == "axial":
            return axial_load(model)
        if direction == JIG:
            from wrist_env.anatomy import jig  # myo-sim's metacarpals: read only for this load

            body, point, pull, share = jig.model_lines(model)
            return Loads(body, point, pull, share, direction)
        body, point, pull, share = model_lines(model, direction)
        return Loads(body, point, pull, share, direction)
    d = np.asarray(direction, dtype=np.float64)
    norm = float(np.linalg.norm(d)) if d.shape == (3,) else np.nan
    if not np.isfinite(norm) or norm < 1e-9:
        raise ValueError(f"load_direction must be a finite, non-zero (3,) vector (RCS), but got {direction!r}")
    return axial_load(model, d / norm)


def static(model: Model, n_frames: int = 3) -> Driver:
    """The capitate held at neutral for `n_frames` frames (experimental driver, identity poses, no load)."""
    n_frames = check_int("n_frames", n_frames, 1, MAX_FRAMES)
    return experimental(model, np.tile(np.eye(4), (n_frames, 1, 1)))


def idealized(
    model: Model,
    *,
    flexion_deg: float = 40.0,
    extension_deg: float = 40.0,
    n_frames: int = 17,
    angles_deg: ArrayLike | None = None,
    load_n: float = IDEALIZED_LOAD_N,
    direction: str | ArrayLike = DEFAULT_LOADS,
) -> Driver:
    """Idealized flexion–extension (preprint 2.2.3.2): the capitate from `flexion_deg` of
    flexion to `extension_deg` of extension about the RCS z axis in `n_frames` equal steps
    (or through `angles_deg`, flexion +), other rotations held, translations free under
    a small compressive load `load_n` (N) along `direction` (see `loaded`). The frames (at most `MAX_FRAMES`)
    and the angles (finite, within +-`MAX_SWEEP_DEG`) are checked before anything is allocated."""
    if angles_deg is None:
        n_frames = check_int("n_frames", n_frames, 1, MAX_FRAMES)
        first = check_float("flexion_deg", flexion_deg, -MAX_SWEEP_DEG, MAX_SWEEP_DEG, "deg")
        last = check_float("extension_deg", extension_deg, -MAX_SWEEP_DEG, MAX_SWEEP_DEG, "deg")
        angle = np.linspace(first, -last, n_frames)
    else:
        angle = np.asarray(angles_deg, float)
        if angle.ndim != 1 or not 1 <= len(angle) <= MAX_FRAMES or not np.all(np.abs(angle) <= MAX_SWEEP_DEG):
            raise InputError(
                f"angles_deg must be 1 to {MAX_FRAMES:,} finite angles within +-{MAX_SWEEP_DEG:g} deg, "
                f"but got shape {angle.shape}, largest |angle| {np.max(np.abs(angle)) if angle.size else None}"
            )
    rotations = Rotation.from_euler("z", angle[:, None], degrees=True).as_matrix()
    return loaded(model, rotations, load_n, angle, direction)


def for_motion(
    model: Model,
    motion: str,
    trial: Trial | None = None,
    *,
    n_frames: int | None = None,
    flexion_deg: float = 40.0,
    extension_deg: float = 40.0,
    direction: str | ArrayLike = DEFAULT_LOADS,
) -> Driver:
    """The driver of a motion (`motions.DRIVEN_MOTIONS`): the one map from a motion's name to a driver.

    Parameters
    ----------
    model : Model
        The participant's model.
    motion : str
        ``"idealized"``: the loaded sweep from `flexion_deg` to `extension_deg` in `n_frames` frames (default
        17; `idealized`); ``"static"``: the capitate held at neutral for `n_frames` frames (default 3;
        `static`); ``"calibrate"`` or ``"validate"``: the experimental driver of that `trial` (`trial_driver`).
    trial : Trial, optional
        The trial of a trial motion (its role's trial of the participant or of an instance); required for
        those, refused for the others.
    n_frames : int, optional
        Frames of the idealized or static motion; a trial has its own (refused).
    flexion_deg, extension_deg : float
        The idealized sweep's first flexion and last extension, deg.
    direction : str or (3,) array_like
        The loads' lines of action (`loads`); the static motion has no load.

    Returns
    -------
    Driver

    Raises
    ------
    InputError
        An unknown motion, a trial motion without its trial, or frames or a trial given to a motion that
        does not take them.
    """
    if motion not in DRIVEN_MOTIONS:
        raise InputError(f"motion must be one of {DRIVEN_MOTIONS}, but got {motion!r}")
    if motion in TRIAL_MOTIONS:
        if trial is None:
            raise InputError(f"the {motion!r} motion is a trial's: give its trial")
        if n_frames is not None:
            raise InputError(
                f"the {motion!r} motion has its trial's {trial.n_frames} frames, but got n_frames={n_frames}"
            )
        return trial_driver(model, trial, direction)
    if trial is not None:
        raise InputError(f"the {motion!r} motion takes no trial")
    frames = {} if n_frames is None else {"n_frames": n_frames}  # else each driver's own default
    if motion == IDEALIZED:
        return idealized(model, flexion_deg=flexion_deg, extension_deg=extension_deg, direction=direction, **frames)
    return static(model, **frames)
