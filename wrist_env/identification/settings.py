"""The Bayesian calibrator's sampler settings: their defaults (which `map`, `mcmc` and `smc` take from here)
and one frozen record that refuses values out of range."""

from __future__ import annotations

import numbers
from dataclasses import dataclass

from wrist_env.design import N_MATERIAL
from wrist_env.errors import InputError
from wrist_env.limits import (
    MAX_CHAIN_DRAWS,
    MAX_MAP_STARTS,
    MAX_MCMC_STEPS,
    MAX_PARTICLES,
    MAX_STEPS,
    MAX_WALKERS,
    check_int,
)

SAMPLERS = ("emcee", "smc")
"""The Bayesian calibrator's samplers: emcee's ensemble MCMC (`mcmc`) or SMCPy's tempered SMC (`smc`)."""
WALKERS = 48
"""emcee's ensemble walkers."""
STEPS = 1200
"""Ensemble steps: at 300 the chains were overconfident even on the model's own trials (docs/history.md, "Status"); ~12 min a run."""
PRIOR_REFRESH = 0.2
"""Share of emcee's moves that are `prior_refresh`; the rest DE (80 %) and DE snooker (20 %)."""
PARTICLES = 256
"""SMC's particles."""
MCMC_STEPS = 5
"""Random-walk Metropolis steps per particle and SMC stage."""
MAP_STARTS = 24
"""Gauss–Newton starts of the MAP search: on P1's model trials (seed 0) 10 of 24 random starts reached
the basin of the best fit (objective 35) and 14 stopped at 91–146; 8 starts all missed it there."""

MIN_STEPS = 8
"""Least ensemble steps: the first half is burn-in and split R-hat halves the kept half again, and each
half needs two steps for its variance (4 steps gave "split R-hat max nan")."""
BOUNDS = {
    "walkers": (2 * N_MATERIAL, MAX_WALKERS, f"2 per material, {N_MATERIAL} materials"),
    "steps": (MIN_STEPS, MAX_STEPS, "half burn-in, the kept half split in two halves of 2+ for R-hat"),
    "particles": (2 * N_MATERIAL, MAX_PARTICLES, f"2 per material, {N_MATERIAL} materials"),
    "mcmc_steps": (1, MAX_MCMC_STEPS, "one move per stage"),
    "map_starts": (1, MAX_MAP_STARTS, "one Gauss-Newton run"),
}
"""(least, most, why) of each integer setting: the ensemble and the particle cloud need two members per
material to span the 22 dimensions (emcee refuses fewer); the most are `wrist_env.limits`'. The command
line's options take the same bounds (`wrist_env.cli.identification_commands`)."""


@dataclass(frozen=True)
class SamplerSettings:
    """What shapes a run of the Bayesian calibrator.

    sampler: "emcee" (`walkers` x `steps`, a share `prior_refresh` in [0, 1) of the moves redraws one
    material from its prior) or "smc" (`particles`, `mcmc_steps` random-walk steps per particle and
    stage); map_starts: Gauss-Newton starts of the MAP search both start from."""

    sampler: str = "emcee"
    walkers: int = WALKERS
    steps: int = STEPS
    particles: int = PARTICLES
    mcmc_steps: int = MCMC_STEPS
    map_starts: int = MAP_STARTS
    prior_refresh: float = PRIOR_REFRESH

    def __post_init__(self):
        if self.sampler not in SAMPLERS:
            raise InputError(f"SamplerSettings.sampler must be one of {SAMPLERS}, but got {self.sampler!r}")
        for name, (least, most, why) in BOUNDS.items():
            object.__setattr__(self, name, check_int(f"SamplerSettings.{name}", getattr(self, name), least, most, why))
        if self.sampler == "emcee" and self.walkers * self.steps > MAX_CHAIN_DRAWS:
            raise InputError(
                f"SamplerSettings.walkers x steps must be at most {MAX_CHAIN_DRAWS:,} (the chain holds every draw), "
                f"but got {self.walkers:,} x {self.steps:,} = {self.walkers * self.steps:,}"
            )
        share = self.prior_refresh
        if not isinstance(share, numbers.Real) or isinstance(share, bool) or not 0 <= share < 1:
            raise InputError(f"SamplerSettings.prior_refresh must be a share in [0, 1), but got {share!r}")
        object.__setattr__(self, "prior_refresh", float(share))

    def record(self) -> dict:
        """The settings that shape a run of this sampler (a saved run records them; the study's table
        lists them): emcee's walkers, steps, map_starts and prior_refresh, or SMC's particles,
        mcmc_steps and map_starts."""
        if self.sampler == "emcee":
            return {
                "walkers": self.walkers,
                "steps": self.steps,
                "map_starts": self.map_starts,
                "prior_refresh": self.prior_refresh,
            }
        return {"particles": self.particles, "mcmc_steps": self.mcmc_steps, "map_starts": self.map_starts}
