"""
A calibration
=============

Calibrate the 22 ligament materials of the built-in participant P1 with
CMA-ES on a small budget, then read what came out: the best design's
kinematic cost on the calibration trial, its cost on the held-out trial, and
how far it lies from P1's hidden ground truth (parameter recovery, in Table 2
SD units). ``wrist_env.bench.calibrate`` is the benchmark's unit of work, so
this is one cell of ``wrist-bench benchmark``.
"""

# %%
# One call runs the calibrator: every batch it asks for is one batched
# solver call on P1's calibration trial. The injury scalars stay intact.
import matplotlib.pyplot as plt
import numpy as np

from wrist_env.bench import calibrate

run = calibrate("P1", "cmaes", budget=20, seed=0)
print(f"calibration trial cost {run.cost:.3f}")
print(f"held-out trial cost {run.validate_cost:.3f}")
print(f"recovery {run.recovery_z:.2f} SD")
print(f"(the population design's: {run.recovery_z_population:.2f} SD)")

# %%
# The run's history holds every evaluation in the order the calibrator told
# them (``run.result.history_fun``, the kinematic cost of each design). The
# best-so-far curve is what the leaderboards' convergence figures draw.
cost = run.result.history_fun
evaluation = np.arange(1, len(cost) + 1)
plt.figure(figsize=(6, 3.5))
plt.plot(evaluation, cost, "o", ms=4, alpha=0.5, label="each design")
best = np.minimum.accumulate(cost)
plt.step(evaluation, best, where="post", label="best so far")
plt.yscale("log")  # a poor design costs many times a good one
plt.xlabel("evaluation")
plt.ylabel("kinematic cost (calibration trial)")
plt.title("CMA-ES on P1")
plt.legend()
plt.tight_layout()

# %%
# The calibrated design in physical units: each ligament's stiffness (N/mm)
# and reference strain (l_ref / l0).
design = run.design.as_dict()
for name in ("SLIL_d", "LRL", "DRC"):
    k, r = design[f"{name}.stiffness"], design[f"{name}.reference_strain"]
    print(f"{name}: {k:.1f} N/mm, reference strain {r:.3f}")
