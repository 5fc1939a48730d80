"""What a simulation is configured by, without the kernels: the solver's settings (`SolverSettings`,
the named `SOLVERS`) and the names of the loads' directions (`LOAD_DIRECTIONS`, `DEFAULT_LOADS`).

`arrays` turns the settings into the kernels' `Settings`; `drivers` turns a load direction into lines of
action. Importing this module loads neither Numba nor the model (the command line declares its options
from it)."""

from __future__ import annotations

from dataclasses import dataclass, replace


@dataclass(frozen=True)
class SolverSettings:
    """Explicit-integration settings (s, mm, N, t).

    dt_s: time step. Each stage ramps the capitate (move_steps to the first
    pose, ramp_steps between frames), then holds it until the free bodies
    are in equilibrium: net force at most max(force_floor_n, tolerance ×
    the largest bundle force) and net moment at most that × 10 mm, after at
    least min_hold_steps and at most max_hold_steps (settling: at most
    settle_steps). damping_per_s: mass-proportional damping of translations
    and rotations; fire_alpha0: FIRE mixing (0 turns FIRE off).
    smooth_normals: contact forces along the grids' nodal gradients
    interpolated trilinearly (continuous), instead of the derivative of the
    trilinear distance (which jumps at cell faces, so no state balances
    exactly: `experiments/verification/solver_accuracy.py`).
    block_mass: one 6×6 mass block per free bone (3×3 for the loaded capitate)
    from the force kernels' tangent (`preconditioner`), rebuilt every
    block_refresh_steps, at each stage and (block_refresh_restart) after each
    FIRE restart; its stiffest mode at dt·ω = block_courant, each bone's soft
    directions floored at block_floor of the stiffest; a bone's step is cut to
    block_max_move_mm (its shift plus rotation × 10 mm).
    membrane_substeps: extra steps of the RSC membrane's free nodes per step,
    the bones held, with mass-proportional damping
    membrane_substep_damping_per_s (`membrane`). predict: start each frame of
    the loaded driver from the secant through the last two frames' equilibria
    (`predictor`), ramping the capitate over predict_ramp_steps instead of
    ramp_steps, where that lowers the residual (the trials' measured poses
    are too noisy to extrapolate: their holds then lock up; docs/solver.md,
    "The preconditioned solver").
    The defaults (issue 32; the default since issue 52) are the block mass, the
    membrane's nodes subcycled 7 steps a step and the secant predictor, with the
    stages they need: ramps of 10 steps, a 60-step move to the first pose (30
    lands P1's and P3's 40° flexion on another equilibrium), at most 150
    settling steps, FIRE's α₀ 0.2, no fibre damping (a viscous term in seconds
    that the block mass's light directions cannot carry: dt·c/m =
    fibre_damping_s / dt_s · block_courant² > 2 at block_courant 1), the mass
    rebuilt every 20 steps and at each stage but not after FIRE's restarts (a
    rebuild costs ~3 steps; rebuilding at the restarts too cost 1.15–1.7× the
    time for about the same steps). Each frame lands as close to a converged
    answer as the diagonal mass's (`diagonal()`) in 2.5–3× fewer steps
    (`experiments/verification/solver_accuracy.py --frame-local`; docs/solver.md).
    mass_scale, inertia_scale: mass scaling of the free bones (inertia_scale
    multiplies rotational inertia on top of mass_scale). node_mass_t: the mass
    of the RSC membrane's free nodes, raised per design where its connectors
    are too stiff for dt_s (`node_mass`). active_band_mm: a
    contact sample is looked up every step while it is within this distance
    of contact (a pair's set is refilled once its samples may have moved half
    of it: `forces.contact_forces`); the rule is exact for bands below
    2/√3 × the grids' margin (`BuildParams.grid_margin_mm`, 3 mm: 3.5 mm), since
    a sample outside its grid reads `contact.OUTSIDE_MM` until a refill.
    """

    dt_s: float = 6e-5
    settle_steps: int = 150
    move_steps: int = 60
    ramp_steps: int = 10
    min_hold_steps: int = 10
    max_hold_steps: int = 1600
    tolerance: float = 0.001
    force_floor_n: float = 0.01
    damping_per_s: float = 100.0
    rot_damping_per_s: float = 100.0
    fibre_damping_s: float = 0.0
    mass_scale: float = 10.0
    inertia_scale: float = 2.0
    active_band_mm: float = 0.15
    node_mass_t: float = 2e-7
    membrane_contact_stiffness: float = 50.0
    max_disp_mm: float = 15.0
    max_rot_deg: float = 75.0
    fire_alpha0: float = 0.2
    smooth_normals: bool = True
    block_mass: bool = True
    block_courant: float = 0.8
    block_floor: float = 0.1
    block_refresh_steps: int = 20
    block_max_move_mm: float = 0.3
    membrane_substeps: int = 7
    membrane_substep_damping_per_s: float = 2000.0
    block_refresh_restart: bool = False
    predict: bool = True
    predict_ramp_steps: int = 0

    def diagonal(self) -> "SolverSettings":
        """These settings with each free bone's scaled physical mass and inertia instead of the block mass
        (the default until issue 52, and the base of the accuracy yardstick's reference runs,
        `experiments/verification/solver_accuracy.py`): no membrane substeps and no predictor, and the
        stages they took: 60-step ramps, a 200-step move to the first pose, at most 800 settling steps,
        FIRE's α₀ 0.1, fibre damping 2e-4 s, and (were the block mass turned on) a rebuild every 10 steps
        and after FIRE's restarts."""
        return replace(
            self,
            block_mass=False,
            fibre_damping_s=2e-4,
            fire_alpha0=0.1,
            settle_steps=800,
            move_steps=200,
            ramp_steps=60,
            block_refresh_steps=10,
            block_refresh_restart=True,
            membrane_substeps=0,
            predict=False,
        )

    def halved(self) -> "SolverSettings":
        """The same run with half the time step (twice the steps)."""
        return replace(
            self,
            dt_s=self.dt_s / 2,
            settle_steps=2 * self.settle_steps,
            move_steps=2 * self.move_steps,
            ramp_steps=2 * self.ramp_steps,
            min_hold_steps=2 * self.min_hold_steps,
            max_hold_steps=2 * self.max_hold_steps,
        )


SOLVERS = ("default", "diagonal")
"""The named solver settings: the defaults (the block mass, issue 32, the default since issue 52) and
`SolverSettings.diagonal` (each bone's scaled physical mass: the default before)."""


def solver_settings(name: str) -> SolverSettings:
    """The settings of a solver in `SOLVERS`."""
    if name not in SOLVERS:
        raise ValueError(f"solver must be one of {SOLVERS}, but got {name!r}")
    return SolverSettings().diagonal() if name == "diagonal" else SolverSettings()


LOAD_DIRECTIONS = ("axial", "erhart2020", "erhart2020_groups", "jig")
"""Named loads: "axial", one compressive line on the capitate along the radius' long axis (`drivers.AXIAL`);
a tendon rig (`anatomy.tendons.RIGS`): each tendon on the body it loads, where it enters the hand; or
"jig", the hand loaded axially through its metacarpals as in Tencer 1988's and Viegas 1993's jigs: one
line along the radius' axis on each distal carpal, shared by CMC facet area (`anatomy.jig`)."""
JIG = "jig"
"""The load mode of the checks measured in an axial jig (`validation`: RS/RL, the midcarpal and ulnar shares)."""
DEFAULT_LOADS = "erhart2020"
"""Every driver's loads unless told otherwise (`LOAD_DIRECTIONS`): the tendons where they enter the hand
(issue 33: under the axial load the radial column carries nothing)."""
