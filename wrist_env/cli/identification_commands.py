"""`wrist-bench` commands on what a trial can identify: sensitivity, identifiability, posterior (their
arguments; `wrist_env.cli.run.identification` runs them)."""

from __future__ import annotations

from collections.abc import Callable

from wrist_env.cli.options import (
    out_option,
    participants_argument,
    progress_option,
    seed_option,
)
from wrist_env.identification.settings import BOUNDS, SAMPLERS, SamplerSettings
from wrist_env.limits import MAX_SEEDS, MAX_SENSITIVITY_N, MIN_SENSITIVITY_N, bounded_float, bounded_int
from wrist_env.motions import MOTIONS

DEFAULTS = SamplerSettings()


def _setting(name: str):
    """The argparse type of the sampler setting `name`: the bounds `SamplerSettings` refuses outside of."""
    return bounded_int(name, *BOUNDS[name])


SAMPLER_OPTIONS = (
    ("walkers", f"ensemble walkers (default %(default)s; >= {BOUNDS['walkers'][0]})"),
    ("steps", f"ensemble steps (default %(default)s, ~12 min a run; >= {BOUNDS['steps'][0]})"),
    ("particles", f"SMC particles (default %(default)s; >= {BOUNDS['particles'][0]})"),
    ("mcmc_steps", "SMC random-walk steps per particle and stage (default %(default)s)"),
    ("map_starts", "Gauss-Newton starts of the MAP search that both samplers start from (default %(default)s)"),
)
"""The posterior's integer `SamplerSettings` as options (--walkers ... --map-starts), each bounded as the settings
are (`BOUNDS`), in the order --help lists them (--sampler after --steps)."""


def add_commands(command: Callable[..., object]) -> None:

    s = command(
        "sensitivity",
        description="Morris screening (n trajectories, n x 23 runs per motion) or Sobol first and total "
        "indices (Saltelli, base n a power of 2, n x 24 runs per motion) of the kinematic cost and the "
        "scaphoid and lunate DOF errors to the 22 ligament materials over the action box (Table 2 mean "
        "+-3 SD), injuries intact, simulated through the vector environment; a CSV and a PNG per participant.",
    )
    participants_argument(s)
    s.add_argument("--method", choices=("morris", "sobol"), default="morris", help="default morris")
    s.add_argument(
        "--n",
        type=bounded_int("n", MIN_SENSITIVITY_N, MAX_SENSITIVITY_N, "Morris trajectories or Sobol base size"),
        default=20,
        help="Morris trajectories or Sobol base size, a power of 2 (default 20)",
    )
    s.add_argument(
        "--motions",
        nargs="+",
        choices=MOTIONS,
        default=list(MOTIONS),
        help="default: all three",
    )
    seed_option(s, "sampling")
    out_option(s, "runs/sensitivity")
    s.set_defaults(run="identification:sensitivity")

    s = command(
        "identifiability",
        description="The Gauss-Newton (Fisher) matrix of the per-frame scaphoid and lunate DOF residuals over "
        "the 4DCT noise (0.2 mm, 0.5 deg), in Table 2 SD units, at each built-in participant's hidden truth "
        "(central differences, 45 runs per trial): its spectrum and each material's posterior SD with the "
        "population prior, for the calibration trial, the held-out trial and both; CSV and a PNG per participant.",
    )
    participants_argument(s, "built-in participants (they have a hidden truth)")
    out_option(s, "runs/identifiability")
    s.set_defaults(run="identification:identifiability")

    s = command(
        "posterior",
        description="Samples the posterior of the 22 ligament materials (Table 2 prior, z units) given the "
        "participant's calibration trial, with the translation and rotation noise scales integrated out, from "
        "the MAP (the best of --map-starts trust-region Gauss-Newton runs): by emcee's ensemble MCMC (one batched "
        "solver call per step, walkers x steps simulations; the first half is burn-in) or by SMCPy's adaptive "
        "tempered SMC bridging from a heavy-tailed start around the MAP (--sampler smc). Per participant and "
        "seed it saves the samples and diagnostics (.npz + .json; a saved run is loaded, not rerun) and "
        "posterior predictive kinematics of both trials; for built-in participants, the coverage of the 50 % "
        "and 90 % credible intervals of the hidden truth (coverage.csv) and a figure of the intervals against "
        "the truth.",
    )
    participants_argument(s)
    s.add_argument(
        "--seeds",
        type=bounded_int("seeds", 1, MAX_SEEDS),
        default=1,
        help="runs per participant, seeds 0 .. N-1 (default 1)",
    )
    for name, help in SAMPLER_OPTIONS:
        flag = "--" + name.replace("_", "-")
        s.add_argument(flag, type=_setting(name), default=getattr(DEFAULTS, name), help=help)
        if name == "steps":  # the sampler's choice between its own settings and emcee's
            s.add_argument(
                "--sampler",
                choices=SAMPLERS,
                default=DEFAULTS.sampler,
                help="emcee (ensemble MCMC from the MAP; default) or smc (SMCPy's adaptive tempered SMC from a "
                "heavy-tailed start around the MAP; files get a _smc suffix)",
            )
    s.add_argument(
        "--prior-refresh",
        type=bounded_float("prior_refresh", 0.0, 1.0),  # 1 itself: SamplerSettings refuses it
        default=DEFAULTS.prior_refresh,
        help="emcee's share of moves that redraw one material from its prior (default %(default)s)",
    )
    out_option(s, "runs/posterior")
    s.add_argument("--report", help="folder of coverage.csv and the figures (default: --out)")
    s.add_argument(
        "--model-trials",
        action="store_true",
        help="calibrate against the model's own run of the hidden truth plus the trials' tracking noise "
        "(no model error: tells the calibrator's honesty from the model's fidelity; files get a _model suffix)",
    )
    progress_option(s)
    s.set_defaults(run="identification:posterior")
