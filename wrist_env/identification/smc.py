"""Adaptive tempered sequential Monte Carlo (SMCPy) over the 22 materials, from the prior or from a
defensive start around the MAP."""

from __future__ import annotations

import numpy as np
from scipy.stats import multivariate_t

from wrist_env import table2
from wrist_env.identification import likelihood

START_DF = 5
START_SCALE = 1.5
"""SMC's start around the MAP: Student-t degrees of freedom and the Laplace covariance's scale (SD)."""
PRIOR_SHARE = 0.2
"""The prior's share of SMC's defensive start."""
TARGET_ESS = 0.5
"""Each SMC stage's effective sample size after reweighting, a share of the particles."""


FAILED_LOG_LIKELIHOOD = -1e6
"""SMC's log likelihood of a failed run: finite (a tempered −inf·0 is NaN) and negligible at any φ > 10⁻³."""


class DefensiveStart:
    """An SMC start: (1 − `PRIOR_SHARE`)·Student-t (ν = `START_DF`, centre `mean`, scale matrix
    `START_SCALE`²·`cov`) truncated to the prior box, plus `PRIOR_SHARE`·prior, the defensive mixture
    of Hesterberg (1995, Technometrics 37:185): heavy tails and the prior so that it covers what the
    Laplace approximation misses. rvs(n, random_state) → (n, 22); logpdf(x (n, 22)) → (n,), normalized."""

    def __init__(self, mean: np.ndarray, cov: np.ndarray):
        self.student = multivariate_t(mean, START_SCALE**2 * cov, df=START_DF)
        self.prior = table2.material_prior(likelihood.BOUND_Z)
        inside = likelihood.in_box(self.student.rvs(100_000, random_state=np.random.default_rng(0)))
        self.log_inside = np.log(max(inside.mean(), 1e-5))  # the truncated t's normalizer, Monte Carlo

    def rvs(self, n: int, random_state=None) -> np.ndarray:
        rng = np.random.default_rng(random_state)
        out = self.prior.rvs(size=(n, len(self.student.loc)), random_state=rng)
        from_t = np.flatnonzero(rng.random(n) >= PRIOR_SHARE)
        draws = np.empty((0, out.shape[1]))
        while len(draws) < len(from_t):
            batch = self.student.rvs(4 * len(from_t) + 16, random_state=rng)
            draws = np.vstack([draws, batch[likelihood.in_box(batch)]])
        out[from_t] = draws[: len(from_t)]
        return out

    def logpdf(self, x: np.ndarray) -> np.ndarray:
        x = np.atleast_2d(x)
        student = np.log1p(-PRIOR_SHARE) + self.student.logpdf(x) - self.log_inside
        prior = np.log(PRIOR_SHARE) + self.prior.logpdf(x).sum(axis=1)
        return np.where(likelihood.in_box(x), np.logaddexp(student, prior), -np.inf)


def sample_smc(
    log_like, dim: int, particles: int, mcmc_steps: int, seed: int, progress: bool = False, start=None
) -> dict:
    """Adaptive tempered SMC (SMCPy) to the posterior, from the prior (`likelihood.log_prior`) or along
    the geometric bridge from `start` (an object with rvs and a normalized logpdf, e.g. `DefensiveStart`).

    log_like: batched log likelihood (n, dim) → (n,). Each stage moves φ (the bridge's exponent) so
    that the reweighted particles keep an ESS of `TARGET_ESS`, resamples, and moves every particle
    `mcmc_steps` random-walk Metropolis steps with the particles' covariance. Returns {"samples"
    (particles, dim), "log_likelihood" (particles,), "phi" (stages + 1,), "acceptance" (stages,): the
    share of particles each stage's moves changed, "log_evidence"}.
    """
    from smcpy import AdaptiveSampler, VectorMCMC, VectorMCMCKernel
    from smcpy.paths import GeometricPath

    class Batched:  # SMCPy's log-likelihood interface: built from (model, data, args), called on (n, dim)
        def __init__(self, model, data, args):
            self.model = model

        def __call__(self, inputs):
            out = np.asarray(self.model(inputs), dtype=np.float64)
            return np.where(np.isfinite(out), out, FAILED_LOG_LIKELIHOOD)

    priors = [table2.material_prior(likelihood.BOUND_Z) for _ in range(dim)]
    mcmc = VectorMCMC(log_like, None, priors, log_like_func=Batched)
    names = [f"z{i}" for i in range(dim)]
    path = GeometricPath(proposal=start)
    kernel = VectorMCMCKernel(mcmc, param_order=names, path=path, rng=np.random.default_rng(seed))
    sampler = AdaptiveSampler(kernel, show_progress_bar=progress)
    steps, log_evidence = sampler.sample(particles, mcmc_steps, target_ess=TARGET_ESS)
    last = steps[-1]
    return {
        "samples": np.column_stack([last.param_dict[k] for k in names]),
        "log_likelihood": np.asarray(last.log_likes).ravel(),
        "phi": np.asarray(sampler.phi_sequence, dtype=np.float64),
        "acceptance": np.array([step.attrs["mutation_ratio"] for step in list(steps)[1:]], dtype=np.float64),
        "log_evidence": float(np.ravel(log_evidence)[-1]),
    }
