"""
A Monte Carlo injury study
==========================

The Monte Carlo study draws ligament designs (materials from Table 2's
distributions, each injurable ligament torn with a probability) and runs
each through the idealized flexion–extension sweep, logging the
radioscaphoid contact and every ligament's force per frame. The full study
has thousands of runs per participant and mixed-effects statistics on top;
this is the same study on P1 at a small n, read back with pandas.
"""

# %%
# ``run_study`` writes a run store (Parquet parts, resumable) into a folder;
# a temporary one here.
import tempfile

import matplotlib.pyplot as plt
import numpy as np

from wrist_env.montecarlo import StudyConfig, read_runs, run_study

out = tempfile.mkdtemp(prefix="montecarlo-")
summary = run_study(StudyConfig(("P1",), n=16, seed=0), out, batch=16)
print(summary.counts["P1"])

# %%
# One row per run: the 27 design variables, which ligaments were torn, and
# per-frame lists (wrist angle, radioscaphoid pressure and area, each
# ligament's force). A run whose contact pressure is beyond the study's
# exclusion threshold is kept in the log and marked ``excluded``.
runs = read_runs(out).to_pandas()
runs["SLIL torn"] = runs[["SLIL_v.torn", "SLIL_p.torn", "SLIL_d.torn"]].any(axis=1)
columns = ["sample_id", "SLIL torn", "RSC.torn", "LRL.torn", "ok", "excluded"]
print(runs[columns].head(8).to_string(index=False))

# %%
# Radioscaphoid peak pressure over the sweep, run by run: the outcome the
# preprint's Table 5 models. Runs with an SLIL bundle torn are drawn in red.
plt.figure(figsize=(6, 3.5))
ok = runs[runs.ok]
for angle, peak, torn in zip(ok.angle_deg, ok.rs_peak_mpa, ok["SLIL torn"]):
    plt.plot(angle, peak, color="tab:red" if torn else "tab:blue", alpha=0.6, lw=1)
plt.plot([], [], color="tab:red", label="an SLIL bundle torn")
plt.plot([], [], color="tab:blue", label="SLIL intact")
plt.xlabel("wrist angle (deg, flexion +)")
plt.ylabel("radioscaphoid peak pressure (MPa)")
plt.title(f"P1, n = {len(ok)} runs")
plt.legend()
plt.tight_layout()

# %%
# A per-run summary, the mean over the sweep, by SLIL state.
ok = ok.assign(rs_mean_over_sweep_mpa=[np.nanmean(v) for v in ok.rs_mean_mpa])
summary = ok.groupby("SLIL torn")["rs_mean_over_sweep_mpa"].describe()
print(summary[["count", "mean", "min", "max"]])
