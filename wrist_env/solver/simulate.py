"""`simulate(model, design, driver)`: one simulation as a recipe, and its batched form.

Drivers: `experimental(model, transforms)` prescribes all 6 DOF of the
capitate from a trial's 4×4 transforms; `loaded(model, rotations, load_n)`
prescribes its rotations and leaves its translations free under a
compressive load (along the radius' axis, `AXIAL`, or any direction: the tendons' resultant is
`anatomy.tendons.resultant_direction`); `idealized(model)` is the loaded driver ramping from
maximum flexion to maximum extension about the RCS z axis.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numba
import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from wrist_env.anatomy.tendons import model_lines
from wrist_env.design import ALL_LIGAMENT_NAMES, Design
from wrist_env.model import CAPITATE, N_BODIES, PAIRS, Model
from wrist_env.solver import arrays, kernel
from wrist_env.solver.rigid import pose_state

if TYPE_CHECKING:
    from wrist_env.trial import Trial

IDEALIZED_LOAD_N = 10.0  # compressive load that keeps the joint in contact (N)
AXIAL = (0.0, 1.0, 0.0)  # the load along the radius' long axis, proximal (RCS +y)
DEFAULT_LOADS = "erhart2020"
"""Every driver's loads unless told otherwise (`LOAD_DIRECTIONS`): the tendons where they enter the hand
(issue 33: under the axial load the radial column carries nothing)."""
STATUS = {
    kernel.OK: "ok",
    kernel.FAILED_NAN: "failed: NaN in the state",
    kernel.FAILED_DIVERGED: "failed: a free bone dislocated (moved beyond max_disp_mm from its place or turned beyond max_rot_deg from the capitate)",
}


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

    def kernel_load(self, frame: int | None = None) -> kernel.Load:
        """The lines of action as the kernel takes them (`kernel.Load`), tensions as `load(frame)`."""
        lines = self.loads
        return kernel.Load(
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
    com = np.tile(model.com[CAPITATE], (n, 1))
    load = np.broadcast_to(np.asarray(load_n, dtype=np.float64), (n,)).copy()
    angle = np.full(n, np.nan) if angle_deg is None else np.asarray(angle_deg, dtype=np.float64)
    return Driver(arrays.LOADED, rotation, com, angle, load, loads(model, direction))


LOAD_DIRECTIONS = ("axial", "erhart2020", "erhart2020_groups")

"""Named loads: "axial", one compressive line on the capitate along the radius' long axis (`AXIAL`), or
a tendon rig (`anatomy.tendons.RIGS`): each tendon on the body it loads, where it enters the hand."""


def loads(model: Model, direction: str | ArrayLike) -> Loads:
    """The `Loads` of a `LOAD_DIRECTIONS` name, or one line on the capitate along a (3,) vector; a wrong
    name or shape, a non-finite or a zero vector is refused."""
    if isinstance(direction, str):
        if direction not in LOAD_DIRECTIONS:
            raise ValueError(f"load_direction must be one of {LOAD_DIRECTIONS} or a (3,) vector, but got {direction!r}")
        if direction == "axial":
            return axial_load(model)

        body, point, pull, share = model_lines(model, direction)
        return Loads(body, point, pull, share, direction)
    d = np.asarray(direction, dtype=np.float64)
    norm = float(np.linalg.norm(d)) if d.shape == (3,) else np.nan
    if not np.isfinite(norm) or norm < 1e-9:
        raise ValueError(f"load_direction must be a finite, non-zero (3,) vector (RCS), but got {direction!r}")
    return axial_load(model, d / norm)


def static(model: Model, n_frames: int = 3) -> Driver:
    """The capitate held at neutral for `n_frames` frames (experimental driver, identity poses, no load)."""
    if int(n_frames) < 1:
        raise ValueError(f"n_frames must be at least 1, but got {n_frames}")
    return experimental(model, np.tile(np.eye(4), (int(n_frames), 1, 1)))


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
    a small compressive load `load_n` (N) along `direction` (see `loaded`)."""
    angle = np.linspace(flexion_deg, -extension_deg, n_frames) if angles_deg is None else np.asarray(angles_deg, float)
    rotations = Rotation.from_euler("z", angle[:, None], degrees=True).as_matrix()
    return loaded(model, rotations, load_n, angle, direction)


@dataclass(frozen=True)
class Result:
    """Per-frame outputs of one simulation.

    poses (n_frames, 6, 4, 4): neutral → frame transforms of `BONES`, RCS mm.
    contact (n_frames, 7, 4): per pair (`model.PAIRS`) mean pressure over the
        contacting area (MPa), peak pressure (MPa), contact area (mm²), force (N).
    bundle_force (n_frames, 16): tension of each ligament, `design.ALL_LIGAMENT_NAMES` order (N).
    energy (n_frames, 2): kinetic and internal energy (N·mm).
    residual (n_frames, 2): largest net force (N) and moment (N·mm) on the free bones.
    steps (n_frames,): explicit steps since the previous frame (ramp + hold to equilibrium;
        frame 0 includes settling and the move to the first pose).
    settled (n_frames,): whether the frame's hold ended in equilibrium (False: it ran out of hold
        steps, and its outputs are where the bones were then).
    membrane_nodes (n_frames, M, 3): the RSC membrane's nodes (`model.membrane_nodes` order), RCS mm.
    status: 0 ok, otherwise failed (see `message`); a failed run's frames are NaN.
    """

    poses: np.ndarray
    contact: np.ndarray
    bundle_force: np.ndarray
    energy: np.ndarray
    residual: np.ndarray
    steps: np.ndarray
    settled: np.ndarray
    membrane_nodes: np.ndarray
    angle_deg: np.ndarray
    status: int
    message: str

    @property
    def ok(self) -> bool:
        return self.status == kernel.OK


def _outputs(n: int, n_frames: int, n_nodes: int) -> kernel.Outputs:
    shape = (n,) if n else ()
    return kernel.Outputs(
        np.full(shape + (n_frames, N_BODIES, 4, 4), np.nan),
        np.full(shape + (n_frames, len(PAIRS), 4), np.nan),
        np.full(shape + (n_frames, len(ALL_LIGAMENT_NAMES)), np.nan),
        np.full(shape + (n_frames, 2), np.nan),
        np.full(shape + (n_frames, 2), np.nan),
        np.zeros(shape + (n_frames,), np.int64),
        np.zeros(shape + (n_frames,), np.int64),
        np.full(shape + (n_frames, n_nodes, 3), np.nan),
        np.zeros(shape + (1,), np.int64),
    )


@dataclass(frozen=True)
class Prepared:
    """A model's kernel arrays under one solver setting and driver mode: built once (`prepare`),
    reused by every `simulate` / `simulate_batch` call that passes it (a `Task` keeps one)."""

    model: Model
    mode: int
    bodies: arrays.Bodies
    grids: arrays.Grids
    fibres: arrays.Fibres
    membrane: arrays.Membrane
    settings: arrays.Settings
    law: np.ndarray
    membrane_eigenvalue: float

    def check(self, model: Model, driver: Driver) -> None:
        if model is not self.model or driver.mode != self.mode:
            raise ValueError(
                f"these prepared arrays are for model {self.model.name!r} and driver mode {self.mode}, "
                f"but got model {model.name!r} and mode {driver.mode}"
            )


def prepare(model: Model, settings: arrays.SolverSettings | None = None, mode: int = arrays.EXPERIMENTAL) -> Prepared:
    """The kernel arrays of `model` under `settings` (default `SolverSettings()`) for drivers of `mode`."""
    s = settings or arrays.SolverSettings()
    grd = arrays.grids(model, s.smooth_normals)
    mem = arrays.membrane(model, grd)
    return Prepared(
        model,
        int(mode),
        arrays.bodies(model, s),
        grd,
        arrays.fibres(model),
        mem,
        arrays.settings_tuple(s, mode),
        np.ascontiguousarray(model.contact_law, dtype=np.float64),
        arrays.membrane_eigenvalue(model, mem),
    )


def stiffness(p: Prepared, design: Design) -> kernel.Stiffness:
    """The kernel's per-design arrays (`arrays.design_arrays`) and the membrane's node mass (`arrays.node_mass`)."""
    f_l0, f_K, m_l0, m_K = arrays.design_arrays(p.model, p.fibres, p.membrane, design)
    return kernel.Stiffness(f_l0, f_K, m_l0, m_K, arrays.node_mass(p.settings, p.membrane_eigenvalue, m_l0, m_K))


def _prepared(model, settings, driver, prepared) -> Prepared:
    if prepared is None:
        return prepare(model, settings, driver.mode)
    prepared.check(model, driver)
    return prepared


def simulate(
    model: Model,
    design: Design,
    driver: Driver,
    settings: arrays.SolverSettings | None = None,
    *,
    prepared: Prepared | None = None,
) -> Result:
    """Simulate one design: settle, move the capitate to the first pose, then the motion.

    prepared: `prepare(model, settings, driver.mode)`, to skip rebuilding the kernel arrays."""
    p = _prepared(model, settings, driver, prepared)
    out = _outputs(0, len(driver.rotation), len(model.membrane_nodes))
    _run(kernel.run, p, stiffness(p, design), driver, out)
    return _result(out, driver, int(out.status[0]))


def simulate_frame(
    model: Model,
    design: Design,
    driver: Driver,
    frame: int,
    poses: np.ndarray,
    nodes: np.ndarray,
    settings: arrays.SolverSettings | None = None,
    *,
    prepared: Prepared | None = None,
) -> Result:
    """Simulate one frame of `driver` (≥ 1) alone, from the state of frame − 1 given as the bones'
    poses (6, 4, 4) and the membrane's nodes (M, 3) mm (another run's answer there): the capitate ramps
    from frame − 1's pose to frame's and holds. A `Result` of two frames, the first left NaN."""
    if not 1 <= frame < driver.n_frames:
        raise ValueError(f"frame must be in 1..{driver.n_frames - 1}, but got {frame}")
    p = _prepared(model, settings, driver, prepared)
    pair = slice(frame - 1, frame + 1)
    two = replace(
        driver,
        rotation=np.ascontiguousarray(driver.rotation[pair]),
        com=np.ascontiguousarray(driver.com[pair]),
        angle_deg=driver.angle_deg[pair],
        load_n=driver.load_n[pair],
    )
    R, x = pose_state(poses, model.com)
    out = _outputs(0, 2, len(model.membrane_nodes))
    frames = _frames(two)
    kernel.run_from(
        p.bodies,
        p.grids,
        p.law,
        p.fibres,
        stiffness(p, design),
        p.membrane,
        p.settings,
        frames,
        out,
        R,
        x,
        np.ascontiguousarray(nodes, dtype=np.float64),
    )
    return _result(out, two, int(out.status[0]))


def simulate_batch(
    model: Model,
    designs: Iterable[Design],
    driver: Driver,
    settings: arrays.SolverSettings | None = None,
    *,
    prepared: Prepared | None = None,
) -> list[Result]:
    """Simulate many designs in parallel (Numba prange); same results as one at a time."""
    p = _prepared(model, settings, driver, prepared)
    per = [stiffness(p, d) for d in designs]
    stacked = kernel.Stiffness(*(np.ascontiguousarray(np.stack(a)) for a in zip(*per)))
    out = _outputs(len(per), len(driver.rotation), len(model.membrane_nodes))
    previous = numba.set_parallel_chunksize(1)  # designs differ in cost: hand them out one at a time
    try:
        _run(kernel.run_batch, p, stacked, driver, out)
    finally:
        numba.set_parallel_chunksize(previous)
    return [_result(kernel.Outputs(*(o[i] for o in out)), driver, int(out.status[i, 0])) for i in range(len(per))]


def _run(entry, p: Prepared, stiffness: kernel.Stiffness, driver: Driver, out: kernel.Outputs) -> None:
    """Call a kernel entry point (`kernel.run` or `kernel.run_batch`) on prepared arrays; fills `out`."""
    frames = _frames(driver)
    entry(p.bodies, p.grids, p.law, p.fibres, stiffness, p.membrane, p.settings, frames, out)


def _frames(driver: Driver) -> kernel.Frames:
    """The driver's targets and loads per frame, as the kernel takes them."""
    body, point, direction, tension = driver.kernel_load()
    return kernel.Frames(driver.rotation, driver.com, tension, body, point, direction)


def _result(out: kernel.Outputs, driver: Driver, status: int) -> Result:
    poses, contact, bundle, energy, residual, steps, settled, nodes, _ = out
    if status != kernel.OK:
        for a in (poses, contact, bundle, energy, residual, nodes):
            a[...] = np.nan
    return Result(
        poses,
        contact,
        bundle,
        energy,
        residual,
        steps,
        settled.astype(bool),
        nodes,
        driver.angle_deg,
        status,
        STATUS[status],
    )
