"""What `wrist-bench figure` draws, computed: the template's surfaces and annotations, and a participant's model
simulated with the population design (and the hidden truth) at neutral and over the idealized sweep. The
figures (`wrist_env.figures`) only draw what these functions return."""

from __future__ import annotations

import numpy as np

from wrist_env import design
from wrist_env.anatomy.annotations import Annotations, template_annotations
from wrist_env.anatomy.template import load_template
from wrist_env.builder.params import BuildParams
from wrist_env.figures.animation import RADIOCARPAL, SweepFrames
from wrist_env.figures.simulation import PRESSURE_PANELS, PressureFrame, RowKinematics
from wrist_env.model import Model
from wrist_env.participants import builtin
from wrist_env.solver import drivers, simulate
from wrist_env.solver.outputs import cardan_deg, pair_slice, pressure_map


def template() -> tuple[dict, Annotations]:
    """The default build's template (swept fossae, distal row): its bone surfaces by name and its
    annotations, as the annotations figure draws them."""
    anatomy = BuildParams().anatomy
    return load_template(*anatomy).bones, template_annotations(*anatomy)


def pressure_frame(model: Model, name: str, *, static: bool = False) -> PressureFrame:
    """The population design's frame at the neutral pose of participant `name`'s `model`. Default: the 0°
    frame of the idealized ±40° sweep (capitate rotation prescribed, translations free under the 10 N
    compressive load); static=True: the capitate held at neutral (experimental driver, identity poses, no
    load). RuntimeError if the simulation fails."""
    if static:
        driver = drivers.static(model)
        frame = len(driver.rotation) - 1
        how = "capitate held at neutral (all 6 DOF), no external load"
    else:
        driver = drivers.idealized(model)
        frame = int(np.argmin(np.abs(driver.angle_deg)))
        load = getattr(driver, "load_n", None)
        how = (
            f"the {driver.angle_deg[frame]:.0f}° frame of the idealized sweep "
            f"(+{driver.angle_deg[0]:.0f}° → {driver.angle_deg[-1]:.0f}°; capitate rotation prescribed, "
            f"translations free under a {10.0 if load is None else float(load[frame]):g} N compressive load)"
        )
    result = simulate.simulate(model, design.population(), driver)
    if not result.ok:
        raise RuntimeError(f"{name}: simulation failed: {result.message}")
    poses = result.poses[frame]
    pairs = [p for _, panel_pairs, _, _ in PRESSURE_PANELS for p in panel_pairs]
    return PressureFrame(
        name, poses, pressure_map(model, poses), result.contact[frame], {p: pair_slice(model, p) for p in pairs}, how
    )


def row_kinematics(model: Model, name: str, *, n_frames: int = 17) -> tuple[np.ndarray, list[RowKinematics]]:
    """The capitate's angle (deg) over the idealized ±40° sweep of `n_frames` frames, and the Cardan angles
    of every body over it with the population design and, for a built-in participant, its hidden truth."""
    driver = drivers.idealized(model, n_frames=n_frames)
    designs = [("population", design.population(), "-")]
    if name in builtin.BUILTIN:
        designs.append(("hidden truth", builtin.truth(name), "--"))
    runs = []
    for label, d, style in designs:
        result = simulate.simulate(model, d, driver)
        angles = cardan_deg(result.poses) if result.ok else None
        runs.append(RowKinematics(label, style, angles, "" if result.ok else result.message))
    return driver.angle_deg, runs


def sweep_frames(model: Model, name: str, *, n_frames: int = 17) -> SweepFrames:
    """The population design's idealized sweep of `n_frames` frames: poses, bundle forces and the
    radiocarpal samples' pressures at every frame. RuntimeError if the sweep fails."""
    driver = drivers.idealized(model, n_frames=n_frames)
    result = simulate.simulate(model, design.population(), driver)
    if not result.ok:
        raise RuntimeError(f"{name}: the population design's sweep failed ({result.message})")
    slices = tuple(pair_slice(model, p) for p in RADIOCARPAL)
    radiocarpal = np.r_[slices]
    pressure = np.array([pressure_map(model, result.poses[f])[radiocarpal] for f in range(n_frames)])
    return SweepFrames(name, driver.angle_deg, result.poses, result.bundle_force, pressure, slices)
