"""How `wrist-bench` runs the commands on what a trial can identify: sensitivity, identifiability, posterior
(declared in `wrist_env.cli.identification_commands`)."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from wrist_env.cli.run.outputs import out_folder
from wrist_env.errors import Interrupted, UsageError
from wrist_env.figures import identifiability as identifiability_figure
from wrist_env.figures import sensitivity as sensitivity_figure
from wrist_env.identification import fisher
from wrist_env.identification import sensitivity as global_sensitivity
from wrist_env.identification.settings import SamplerSettings
from wrist_env.identification.study import study
from wrist_env.participants import builtin, registry


def sensitivity(args) -> int:

    registry.require(*args.participants)
    for participant in args.participants:
        start = time.perf_counter()
        table = global_sensitivity.study(participant, args.method, args.n, tuple(args.motions), args.seed, args.out)
        sensitivity_figure.plot(table, args.method, Path(args.out) / f"sensitivity_{participant}_{args.method}.png")
        key = "mu_star" if args.method == "morris" else "ST"
        for motion, rows in table[table["output"] == "cost"].groupby("motion", sort=False):
            top = rows.nlargest(5, key)
            ranked = ", ".join(f"{m} {v:.3g}" for m, v in zip(top["material"], top[key]))
            print(f"{participant} {motion}: cost {key} {ranked} ({rows['runs'].iloc[0]} runs)")
        print(
            f"{participant}: {args.out}/sensitivity_{participant}_{args.method}.csv and .png "
            f"in {time.perf_counter() - start:.0f} s",
            flush=True,
        )
    return 0


def identifiability(args) -> int:

    unknown = [p for p in args.participants if p not in builtin.BUILTIN]
    if unknown:
        raise UsageError(f"{unknown} have no hidden truth; built-ins: {list(builtin.BUILTIN)}")
    materials, spectra = fisher.study(args.participants, args.out)
    for participant in args.participants:
        identifiability_figure.plot(
            materials, spectra, participant, Path(args.out) / f"identifiability_{participant}.png"
        )
    for (participant, trials), rows in materials.groupby(["participant", "trials"], sort=False):
        s = spectra[(spectra["participant"] == participant) & (spectra["trials"] == trials)]
        pinned = rows[rows["posterior_sd"] < 0.5]["material"].tolist()
        print(
            f"{participant} {trials}: {int((s['sd'] < 1).sum())} of 22 directions pinned tighter than the prior; "
            f"materials to < 0.5 SD: {', '.join(pinned) or 'none'}"
        )
    print(f"written to {args.out}")
    return 0


def _rhat(rhat: np.ndarray) -> str:
    """The largest split R-hat, or why there is none (a run saved from a chain too short to split, or whose
    walkers never moved: no within-half variance)."""
    finite = rhat[np.isfinite(rhat)]
    if finite.size == 0:
        return "split R-hat not available (the kept chain is too short to split, or no walker moved)"
    return f"split R-hat max {finite.max():.2f}"


def posterior(args) -> int:

    registry.require(*args.participants)
    no_truth = [p for p in args.participants if p not in builtin.BUILTIN]
    if args.model_trials and no_truth:
        raise UsageError(
            f"--model-trials simulates a participant's hidden truth, which {', '.join(no_truth)} (read from a "
            f"folder) does not have; leave --model-trials out, or give built-in participants {list(builtin.BUILTIN)}"
        )
    out_folder(args.out)
    if args.report is not None:
        out_folder(args.report, "--report")
    settings = SamplerSettings(
        args.sampler, args.walkers, args.steps, args.particles, args.mcmc_steps, args.map_starts, args.prior_refresh
    )

    def report(post, loaded):
        how = (
            "loaded from"
            if loaded
            else f"sampled in {post.wall_seconds / 60:.1f} min ({post.evaluations} simulations),"
        )
        mixing = (
            f"ESS min {np.nanmin(post.ess):.0f}, {_rhat(post.rhat)}"
            if post.sampler == "emcee"
            else f"{post.stages} stages, {post.ess[0]:.0f} distinct particles, log evidence {post.log_evidence:.1f}"
        )
        print(
            f"{post.participant} seed {post.seed}: {how} {args.out}; acceptance {post.acceptance:.2f}, "
            f"{mixing}, noise {post.noise[0]:.2f} mm / {post.noise[1]:.2f} deg",
            flush=True,
        )

    try:
        table = study(
            args.participants,
            args.seeds,
            args.out,
            settings,
            progress=not args.no_progress,
            on_run=report,
            report=args.report,
            trials="model" if args.model_trials else "built-in",
        )
    except KeyboardInterrupt:
        saved = len(list(Path(args.out).glob("posterior_*.json")))
        raise Interrupted(
            f"posterior interrupted; {saved} finished run(s) saved in {args.out} are kept and loaded, not sampled "
            "again, on a rerun (the run in progress starts over): rerun the same command to resume"
        ) from None
    if "coverage_90" in table:
        for participant, rows in table.groupby("participant", sort=False):
            print(
                f"{participant}: 50 % intervals cover {rows.coverage_50.mean():.0%}, 90 % cover "
                f"{rows.coverage_90.mean():.0%} of the 22 true materials; recovery of the posterior mean "
                f"{rows.recovery_mean.median():.2f} SD (population {rows.recovery_population.iloc[0]:.2f})"
            )
        print(
            f"all: 50 % intervals cover {table.coverage_50.mean():.0%}, 90 % cover {table.coverage_90.mean():.0%} "
            f"({len(table)} runs)"
        )
    print(f"written to {args.out}" + (f" (table and figures: {args.report})" if args.report else ""))
    return 0
