"""
Reading a benchmark's run log with pandas
=========================================

``wrist-bench benchmark`` (``wrist_env.bench.benchmark``) logs every
evaluation of every cell (participant × instance × calibrator × seed) as a
Parquet row, so a benchmark can be stopped and resumed, and read back into
pandas for any analysis the leaderboards do not make. This example runs a
tiny benchmark into a temporary folder, then reads its log.
"""

# %%
# Two calibrators, one seed, a small budget, in this process
# (``workers=1``; the command line's default is a process per core).
import tempfile

import matplotlib.pyplot as plt

from wrist_env.bench import RunLog, benchmark

out = tempfile.mkdtemp(prefix="benchmark-")
report = benchmark(
    ["P1"],
    ["random", "lhs"],
    seeds=1,
    budget=16,
    out_dir=out,
    workers=1,
    progress=False,
)
print(f"{report.evaluations} evaluations logged in {out}")

# %%
# ``RunLog.read`` is the whole log as a DataFrame: one row per evaluation,
# with the run key, its index in the run (``eval``), the 22 normalized
# materials (``x.<name>``), the kinematic cost and the per-DOF RMSE
# (``rmse.<bone>.<DOF>``, mm and deg).
log = RunLog(out).read()
print(log.shape)
columns = ["participant", "optimizer", "seed", "eval", "batch", "cost", "failed"]
print(log[columns].head(8).to_string(index=False))

# %%
# Best so far per calibrator: a ``groupby`` and a cumulative minimum in the
# order of evaluation.
log = log.sort_values(["optimizer", "seed", "eval"])
log["best_so_far"] = log.groupby(["optimizer", "seed"])["cost"].cummin()
plt.figure(figsize=(6, 3.5))
for name, run in log.groupby("optimizer"):
    plt.step(run["eval"] + 1, run["best_so_far"], where="post", label=name)
plt.xlabel("evaluation")
plt.ylabel("best kinematic cost so far")
plt.title("P1, seed 0")
plt.legend()
plt.tight_layout()

# %%
# Each finished cell also has a JSON summary: the calibrated design, its
# held-out cost and its parameter recovery.
for cell in RunLog(out).summaries():
    held_out = cell["validate"]["cost"]
    print(f"{cell['optimizer']}: best {cell['best_cost']:.3f}, held-out {held_out:.3f}")
    print(f"  recovery {cell['recovery_z']:.2f} SD")
