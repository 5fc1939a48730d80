"""emcee's ensemble MCMC over the 22 materials: the batched log posterior of a calibration task, the
prior-refresh move, the run and its diagnostics (τ, ESS, split R̂)."""

from __future__ import annotations

import logging
from collections.abc import Callable

import emcee
import numpy as np

from wrist_env import design, table2
from wrist_env.identification import likelihood
from wrist_env.identification.settings import PRIOR_REFRESH
from wrist_env.task import Task


def log_likelihood(calibration: Task, counter: list | None = None) -> Callable[[np.ndarray], np.ndarray]:
    """The batched log likelihood (W, 22) → (W,) of z on the calibration trial; −inf where a run fails."""
    base = design.population()

    def log_like(Z):
        Z = np.atleast_2d(Z)
        evaluations = calibration.evaluate_batch([table2.with_z(base, z) for z in Z])
        if counter is not None:
            counter[0] += len(Z)
        return np.array(
            [
                -np.inf if e.failed else likelihood.log_likelihood(likelihood.residuals(calibration, e.result.poses))
                for e in evaluations
            ]
        )

    return log_like


def log_probability(calibration: Task, counter: list | None = None) -> Callable[[np.ndarray], np.ndarray]:
    """The batched log posterior (W, 22) → (W,) of z on the calibration trial (no run outside |z| ≤ 3)."""
    log_like = log_likelihood(calibration, counter)

    def log_prob(Z):
        Z = np.atleast_2d(Z)
        out = likelihood.log_prior(Z)
        inside = np.flatnonzero(np.isfinite(out))
        if len(inside):
            out[inside] += log_like(Z[inside])
        return out

    return log_prob


def prior_refresh(coords: np.ndarray, random) -> tuple[np.ndarray, np.ndarray]:
    """An emcee proposal (`emcee.moves.MHMove`): one material per walker drawn afresh from its prior,
    a Metropolis-within-Gibbs independence move. Returns the proposal (W, 22) and the Hastings
    factors log π(old) − log π(new), which cancel the prior in the acceptance: a ligament that is
    slack over a range of its reference strain is accepted anywhere in that range in one move."""
    n, dim = coords.shape
    rows, which = np.arange(n), random.randint(dim, size=n)
    old = coords[rows, which]
    new = table2.material_prior(likelihood.BOUND_Z).rvs(size=n, random_state=random)
    factors = np.where(np.abs(old) <= likelihood.BOUND_Z, 0.5 * (new**2 - old**2), -np.inf)
    out = coords.copy()
    out[rows, which] = new
    return out, factors


def sample(
    log_prob, start: np.ndarray, steps: int, seed: int, progress: bool = False, refresh: float = PRIOR_REFRESH
) -> dict:
    """Run emcee from `start` (walkers, dim) for `steps`, a share `refresh` of the moves `prior_refresh`;
    the second half kept.

    Returns {"chain": (kept, walkers, dim), "log_prob": (kept, walkers), "acceptance",
    "autocorr" (dim,), "ess" (dim,), "rhat" (dim,)}.
    """
    logging.getLogger("emcee").setLevel(logging.ERROR)  # a short chain's τ is reported, not warned about
    walkers, dim = start.shape
    moves = [
        (emcee.moves.DEMove(), 0.8 * (1 - refresh)),
        (emcee.moves.DESnookerMove(), 0.2 * (1 - refresh)),
    ] + ([(emcee.moves.MHMove(prior_refresh), refresh)] if refresh > 0 else [])
    sampler = emcee.EnsembleSampler(walkers, dim, log_prob, moves=moves, vectorize=True)
    sampler.random_state = np.random.RandomState(seed).get_state()
    sampler.run_mcmc(start, steps, progress=progress)
    burn = steps // 2
    chain = sampler.get_chain(discard=burn)
    moved = np.ptp(chain, axis=0).min(axis=1) > 0  # a walker that never moved has no autocorrelation
    tau = np.maximum(emcee.autocorr.integrated_time(chain[:, moved], quiet=True), 1.0)
    return {
        "chain": chain,
        "log_prob": sampler.get_log_prob(discard=burn),
        "acceptance": float(np.mean(sampler.acceptance_fraction)),
        "autocorr": tau,
        "ess": chain.shape[0] * walkers / tau,
        "rhat": split_rhat(chain),
    }


def split_rhat(chain: np.ndarray) -> np.ndarray:
    """Split R̂ (dim,) of a chain (steps, chains, dim): each chain's halves as two chains (BDA3 §11.4)."""
    n = chain.shape[0] // 2
    halves = np.concatenate([chain[:n], chain[n : 2 * n]], axis=1)  # (n, 2·chains, dim)
    within = halves.var(axis=0, ddof=1).mean(axis=0)
    between = n * halves.mean(axis=0).var(axis=0, ddof=1)
    return np.sqrt(((n - 1) / n * within + between / n) / within)
