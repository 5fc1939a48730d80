"""What a trial can identify, and calibration as inference over the 22 ligament materials.

- `likelihood`: the one owner of the likelihood, the prior and the MAP objective.
- `sensitivity` (Morris, Sobol; SALib) and `fisher` (the Fisher matrix at the hidden truth): how much a
  trial says about each material.
- The Bayesian calibrator: `map` (the MAP and its Laplace covariance), `mcmc` (emcee) or `smc` (SMCPy)
  from there, `bayes.calibrate` (one run: a `posterior.Posterior`) with a `settings.SamplerSettings`,
  `study` (runs, coverage, figures).
"""

__all__: list[str] = []  # the modules are the API: nothing is imported here
