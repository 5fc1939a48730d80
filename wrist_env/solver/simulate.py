"""`simulate(model, design, driver)`: one simulation as a recipe (prepare → stage, hold, record in the
kernel → a `Result`), and its batched form. The drivers are `drivers`'.
"""

from __future__ import annotations

from collections.abc import Iterable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numba
import numpy as np

from wrist_env.design import Design, population
from wrist_env.ligaments import ALL_LIGAMENT_NAMES
from wrist_env.model import N_BODIES, PAIRS, Model
from wrist_env.solver import arrays, kernel, precompile, step
from wrist_env.solver.drivers import Driver, static
from wrist_env.solver.rigid import pose_state
from wrist_env.solver.settings import SolverSettings

if TYPE_CHECKING:
    pass

STATUS = {
    kernel.OK: "ok",
    kernel.FAILED_NAN: "failed: NaN in the state",
    kernel.FAILED_DIVERGED: "failed: a free bone dislocated (moved beyond max_disp_mm from its place or turned beyond max_rot_deg from the capitate)",
}


@dataclass(frozen=True)
class Result:
    """Per-frame outputs of one simulation.

    poses (n_frames, n_bodies, 4, 4): neutral → frame transforms of `model.BONES`, RCS mm.
    contact (n_frames, n_pairs, 4): per pair (`model.PAIRS`) mean pressure over the
        contacting area (MPa), peak pressure (MPa), contact area (mm²), force (N).
    bundle_force (n_frames, n_bundles): tension of each ligament, `ligaments.ALL_LIGAMENT_NAMES` order (N).
    energy (n_frames, 2): kinetic and internal energy (N·mm).
    residual (n_frames, 2): largest net force (N) and moment (N·mm) on the free bones.
    steps (n_frames,): explicit steps since the previous frame (ramp + hold to equilibrium;
        frame 0 includes settling and the move to the first pose).
    settled (n_frames,): whether the frame's hold ended in equilibrium (False: it ran out of hold
        steps, and its outputs are where the bones were then).
    membrane_nodes (n_frames, n_nodes, 3): the RSC membrane's nodes (`model.membrane_nodes` order), RCS mm.
    angle_deg (n_frames,): the driver's wrist flexion angle per frame (deg, flexion +), NaN for a trial.
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

    @property
    def system(self) -> arrays.System:
        """The arrays every kernel reads (`arrays.System`)."""
        return arrays.System(self.bodies, self.grids, self.law, self.fibres, self.membrane, self.settings)

    def check(self, model: Model, driver: Driver) -> None:
        if model is not self.model or driver.mode != self.mode:
            raise ValueError(
                f"these prepared arrays are for model {self.model.name!r} and driver mode {self.mode}, "
                f"but got model {model.name!r} and mode {driver.mode}"
            )


def prepare(model: Model, settings: SolverSettings | None = None, mode: int = arrays.EXPERIMENTAL) -> Prepared:
    """The kernel arrays of `model` under `settings` (default `SolverSettings()`) for drivers of `mode`."""
    s = settings or SolverSettings()
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


def stiffness(p: Prepared, design: Design) -> step.Stiffness:
    """The kernel's per-design arrays (`arrays.design_arrays`) and the membrane's node mass (`arrays.node_mass`)."""
    f_l0, f_K, m_l0, m_K = arrays.design_arrays(p.model, p.fibres, p.membrane, design)
    return step.Stiffness(f_l0, f_K, m_l0, m_K, arrays.node_mass(p.settings, p.membrane_eigenvalue, m_l0, m_K))


def _prepared(model, settings, driver, prepared) -> Prepared:
    if prepared is None:
        return prepare(model, settings, driver.mode)
    prepared.check(model, driver)
    return prepared


def simulate(
    model: Model,
    design: Design,
    driver: Driver,
    settings: SolverSettings | None = None,
    *,
    prepared: Prepared | None = None,
) -> Result:
    """Simulate one design of one model through one driver's frames.

    The run is a recipe: settle the free bones from rest, move the capitate to the driver's first pose,
    then for every frame ramp the capitate to its pose and hold until the free bones are in equilibrium
    (the explicit kernel, `solver.kernel`). It does not raise on a failed run: a run that diverges
    or meets a NaN returns with `status` set and its frames NaN, so a batch of designs is never cut short.

    Parameters
    ----------
    model : Model
        A participant's built model (`participants.registry.load_model`).
    design : Design
        The 27 ligament variables in physical units (`design.from_action` for a normalized action).
    driver : Driver
        The capitate's targets and the loads, frame by frame: a trial's (`drivers.trial_driver`), the
        idealized sweep (`drivers.idealized`) or the capitate held (`drivers.static`).
    settings : SolverSettings, optional
        The solver's settings; `SolverSettings()`, the default solver, when None.
    prepared : Prepared, optional
        `prepare(model, settings, driver.mode)`, to skip rebuilding the kernel arrays when many designs
        are simulated on one model.

    Returns
    -------
    Result
        Per frame: the bones' poses (n_frames, n_bodies, 4, 4), RCS mm; contact per pair
        (n_frames, n_pairs, 4), MPa, mm² and N; each bundle's tension (n_frames, n_bundles), N; the
        energies, residuals and steps; `status` 0 (`Result.ok`) or the reason it failed (`message`).

    Raises
    ------
    ValueError
        `prepared` was made for another model or another driver mode.

    See Also
    --------
    simulate_batch : many designs in one call, on every Numba thread.
    wrist_env.task.Task : a model, a driver and a reference trial together, scoring designs by their cost.

    Examples
    --------
    >>> from wrist_env import design
    >>> from wrist_env.participants import registry
    >>> from wrist_env.solver import drivers
    >>> from wrist_env.solver.simulate import simulate
    >>> model = registry.load_model("P1")
    >>> result = simulate(model, design.population(), drivers.idealized(model, n_frames=5))
    >>> result.ok, result.poses.shape  # (n_frames, n_bodies, 4, 4)
    (True, (5, 7, 4, 4))
    """
    p = _prepared(model, settings, driver, prepared)
    out = _outputs(0, len(driver.rotation), len(model.membrane_nodes))
    with precompile.compiling(p.settings, p.model) as entry:
        _run(entry, p, stiffness(p, design), _frames(driver), out)
    return _result(out, driver, int(out.status[0]))


def _run(entry, p: Prepared, design: step.Stiffness, frames: kernel.Frames, out: kernel.Outputs) -> None:
    """The kernel's `entry` point (`kernel.entry`) for one design from rest (rotations identity, bones and
    membrane nodes at their neutral places), filling `out`."""
    R = np.repeat(np.eye(3)[None], N_BODIES, axis=0)
    entry(*p.system, design, frames, out, R, p.bodies.com0.copy(), p.membrane.rest.copy(), kernel.SETTLE)


def simulate_frame(
    model: Model,
    design: Design,
    driver: Driver,
    frame: int,
    poses: np.ndarray,
    nodes: np.ndarray,
    settings: SolverSettings | None = None,
    *,
    prepared: Prepared | None = None,
) -> Result:
    """Simulate one frame of `driver` (≥ 1) alone, from the state of frame − 1 given as the bones'
    poses (n_bodies, 4, 4) and the membrane's nodes (n_nodes, 3) mm (another run's answer there): the capitate ramps
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
    nodes = np.array(nodes, dtype=np.float64)  # a copy: the kernel moves it
    with precompile.compiling(p.settings, p.model) as entry:
        entry(*p.system, stiffness(p, design), frames, out, R, x, nodes, 1)  # pose_state's own arrays
    return _result(out, two, int(out.status[0]))


def simulate_batch(
    model: Model,
    designs: Iterable[Design],
    driver: Driver,
    settings: SolverSettings | None = None,
    *,
    prepared: Prepared | None = None,
) -> list[Result]:
    """Simulate many designs in parallel, on `numba.get_num_threads()` threads (the kernel releases the
    GIL), handed out one at a time (designs differ in cost); same results as one at a time."""
    p = _prepared(model, settings, driver, prepared)
    per = [stiffness(p, d) for d in designs]
    frames = _frames(driver)
    out = _outputs(len(per), len(driver.rotation), len(model.membrane_nodes))
    mine = [kernel.Outputs(*(o[i] for o in out)) for i in range(len(per))]
    threads = max(1, min(numba.get_num_threads(), len(per)))
    with precompile.compiling(p.settings, p.model) as entry, ThreadPoolExecutor(threads) as pool:
        list(pool.map(lambda i: _run(entry, p, per[i], frames, mine[i]), range(len(per))))
    return [_result(filled, driver, int(filled.status[0])) for filled in mine]


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


def warm(model: Model, settings: SolverSettings | None = None) -> None:
    """Compile (or load from Numba's cache) the kernel entry point for `settings` (default
    `SolverSettings()`) by simulating `model` held at neutral for one frame (the kernel's types do not depend
    on the model's sizes): called before local worker processes start, so that they load the compiled kernel
    instead of each compiling it (from an empty cache, the block mass's kernels compile in a second process
    meanwhile: `precompile`)."""
    simulate(model, population(), static(model, 1), settings)
