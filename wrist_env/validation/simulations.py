"""The runs every validation check reads, simulated once (`run_simulations`), and what is measured on them
once: the checks of `validation.chain` are pure functions of a `Simulations`, so adding a check adds no
simulation unless it needs a new load mode."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wrist_env import design as design_mod
from wrist_env.anatomy.ulnar_variance import built_variance
from wrist_env.model import BONES, PAIRS, Model
from wrist_env.solver import drivers
from wrist_env.solver import simulate as sim
from wrist_env.solver.outputs import cardan_deg
from wrist_env.solver.settings import JIG
from wrist_env.validation.bands import NEUTRAL_LOAD_N, SLIL
from wrist_env.validation.measures import load_shares_pct, sl_gap_mm, with_tears

RS, RL = PAIRS.index("radioscaphoid"), PAIRS.index("radiolunate")

LOAD_MODES = {
    "sweep": "the idealized +-40 deg flexion-extension sweep, intact, under the sweeps' load (`validate(load_n=..., "
    "load_direction=...)`; by default `drivers.IDEALIZED_LOAD_N` along `settings.DEFAULT_LOADS`)",
    "torn sweep": "the same sweep intact and with all three SLIL bundles torn (one batched call)",
    "jig": f"the capitate held at neutral under {NEUTRAL_LOAD_N:g} N, the hand loaded axially as in the jigs of "
    "Palmer & Werner 1984, Tencer 1988, Hara 1992 and Viegas 1993 (`anatomy.jig`; `validate(neutral_load=...)` "
    "loads it otherwise)",
}
"""The load modes of the checks, in words: which runs a check reads (`RUNS`)."""
RUNS = {"sweep": ("intact",), "torn sweep": ("intact", "torn"), "jig": ("neutral",)}
"""The runs (`Simulations` fields) of each load mode: all must have run for its checks to be measured."""


@dataclass(frozen=True, eq=False)
class Simulations:
    """The population design's three runs and the measures several checks or the figure share.

    Parameters
    ----------
    model : Model
        The participant's model.
    intact, torn : Result
        The idealized flexion–extension sweep, intact and with all three SLIL bundles torn (one batched
        call).
    neutral : Result
        The capitate held at neutral under `NEUTRAL_LOAD_N` N, loaded as `neutral_load`.
    neutral_load : str
        How the neutral run was loaded (`settings.LOAD_DIRECTIONS`; the jig by default).
    flexion_deg : ndarray, shape (n_frames, 3)
        Capitate, scaphoid and lunate flexion (+) over the intact sweep (Cardan, about the RCS z axis), deg.
    sl_gap_intact_mm, sl_gap_torn_mm : ndarray, shape (n_frames,)
        The scapholunate gap, bone surface to bone surface, mm.
    slil_force_n : ndarray, shape (n_frames,)
        SLIL_v + SLIL_p + SLIL_d tension, intact, N.
    shares_pct : dict of str to float
        `measures.load_shares_pct` of the neutral run, %.
    """

    model: Model
    intact: sim.Result
    torn: sim.Result
    neutral: sim.Result
    neutral_load: str
    flexion_deg: np.ndarray
    sl_gap_intact_mm: np.ndarray
    sl_gap_torn_mm: np.ndarray
    slil_force_n: np.ndarray
    shares_pct: dict

    def failure(self, load: str) -> str | None:
        """Why the runs of a load mode (`LOAD_MODES`) cannot be measured (the first that failed), or None."""
        labels = {"intact": "intact sweep", "torn": "SLIL-torn sweep", "neutral": "neutral"}
        failed = (f"{labels[r]} run {getattr(self, r).message}" for r in RUNS[load] if not getattr(self, r).ok)
        return next(failed, None)

    @property
    def words(self) -> dict[str, str]:
        """What a check's description (`CheckSpec.description`) fills in: the neutral load, and the ulnar
        variance as the build seated the ulna (the ulnar share depends on it, Werner 1986; "" where the
        corner rule found none)."""
        mode = "the hand loaded axially, as in a jig" if self.neutral_load == JIG else f"the {self.neutral_load} load"
        v = built_variance(self.model.report)
        return {
            "neutral": f"{NEUTRAL_LOAD_N:g} N ({mode})",
            "ulnar_variance": "" if v is None else f", ulnar variance {v:+.2f} mm",
        }

    def series(self) -> dict:
        """The per-frame series behind the checks and the figure, and each run's status (the record's)."""
        cap, sca, lun = self.flexion_deg.T
        return {
            "capitate_angle_deg": self.intact.angle_deg,
            "capitate_flexion_deg": cap,
            "scaphoid_flexion_deg": sca,
            "lunate_flexion_deg": lun,
            "sl_gap_intact_mm": self.sl_gap_intact_mm,
            "sl_gap_slil_torn_mm": self.sl_gap_torn_mm,
            "slil_force_intact_n": self.slil_force_n,
            "rs_mean_pressure_intact_mpa": self.intact.contact[:, RS, 0],
            "intact_status": self.intact.message,
            "slil_torn_status": self.torn.message,
            "neutral_status": self.neutral.message,
        }


def run_simulations(
    model: Model,
    intact_design: design_mod.Design,
    *,
    n_frames: int,
    load_n: float,
    load_direction: str,
    neutral_load: str,
    settings=None,
) -> Simulations:
    """Simulate a design three times for the checks, then measure what the checks share.

    The idealized sweep intact and SLIL-torn in one batch, and the neutral pose under `NEUTRAL_LOAD_N` N
    loaded as `neutral_load`.

    Parameters
    ----------
    model : Model
        The participant's model.
    intact_design : Design
        The design simulated (the population design in `validate`); the torn run tears its three SLIL
        bundles.
    n_frames : int
        Frames of the idealized sweep.
    load_n : float
        The sweeps' compressive load, N.
    load_direction : str
        The sweeps' load direction (`settings.LOAD_DIRECTIONS`).
    neutral_load : str
        The load at neutral (`settings.LOAD_DIRECTIONS`; `settings.JIG` for the jig).
    settings : SolverSettings, optional
        The solver's settings (default: its defaults).

    Returns
    -------
    Simulations
        The three runs and the shared measures.
    """
    torn_design = with_tears(intact_design, SLIL)
    sweep = drivers.idealized(model, n_frames=n_frames, load_n=load_n, direction=load_direction)
    intact, torn = sim.simulate_batch(model, [intact_design, torn_design], sweep, settings)
    neutral = sim.simulate(
        model,
        intact_design,
        drivers.loaded(model, [np.eye(3)], load_n=NEUTRAL_LOAD_N, direction=neutral_load),
        settings,
    )
    bones = [BONES.index(bone) for bone in ("capitate", "scaphoid", "lunate")]
    slil = [design_mod.LIGAMENT_NAMES.index(n) for n in SLIL]
    return Simulations(
        model=model,
        intact=intact,
        torn=torn,
        neutral=neutral,
        neutral_load=neutral_load,
        flexion_deg=cardan_deg(intact.poses)[..., 0][:, bones],
        sl_gap_intact_mm=sl_gap_mm(model, intact.poses),
        sl_gap_torn_mm=sl_gap_mm(model, torn.poses),
        slil_force_n=intact.bundle_force[:, slil].sum(axis=1),
        shares_pct=load_shares_pct(model, neutral),
    )
