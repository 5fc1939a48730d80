"""Leaderboards of a benchmark run log: tables (Markdown, CSV) and COCO-style figures (PNG).

`write_leaderboard(runs, out)` reads the run log in `runs` (finished cells
only) and writes to the folder `out`:

- best_cost.csv: best calibration cost at the budget per participant and calibrator, median and
  IQR (25th–75th percentile) over seeds;
- targets.csv, evals_to_target.csv: evaluations to reach each cost target (TARGETS), the number
  of runs that reached it and COCO's expected running time (ERT);
- ecdf.png: COCO-style ECDF of (run, target) pairs solved against evaluations;
  convergence.png: best-so-far cost against evaluations, median and IQR band per calibrator,
  one panel per participant;
- recovery.csv: parameter-recovery error (RMS z-score difference to the hidden truth);
- heldout.csv: the calibrated design (best of each run) on the held-out resisted trial;
- table3_rmse_calibrate.csv, table4_rmse_validate.csv: the preprint's Tables 3–4, per participant,
  bone and DOF: RMSE of the population and the calibrated design (the best run per participant);
  dof_improved.csv: the share of DOF whose RMSE calibration lowered (preprint: 66.7 %, 61.1 %);
- runs.csv: one row per run; README.md: all tables in Markdown with the figures.

Nothing here depends on wall-clock time, so an interrupted-and-resumed
benchmark gives the same CSVs as an uninterrupted one.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from wrist_env.bench.log import RunLog
from wrist_env.cost import COST_BONES
from wrist_env.frames import DOF_NAMES, DOF_UNITS

TARGETS = (("pop×0.75", "population", 0.75), ("pop×0.5", "population", 0.5), ("truth×1.1", "truth", 1.1))
"""Cost targets (name, reference, factor): a target is factor × the reference design's cost on the
calibration trial. 0.75 and 0.5 × the population (Table 2 means) cost measure progress from the
uncalibrated model; 1.1 × the hidden truth's cost is "as good as the truth, within 10 %" (the truth
is not cost 0: the reference kinematics carry tracking noise and come from a finer model). A target
below what any design can reach (0.5 × population can be below the truth's cost) stays unsolved."""

PREPRINT_SHARE_IMPROVED = {"calibrate": 66.7, "validate": 61.1}
"""Share of DOF (%) with lower RMSE after calibration in the preprint's Tables 3 and 4."""


@dataclass
class Reference:
    """A participant's population (and, if built in, hidden-truth) design scored on both trials."""

    participant: str
    population: dict  # {"calibrate": score, "validate": score}; score = {"cost", "failed", "rmse"}
    truth: dict | None


def _score(evaluation) -> dict:
    return {"cost": float(evaluation.cost), "failed": bool(evaluation.failed), "rmse": evaluation.info.get("rmse")}


def reference(participant: str) -> Reference:
    """Simulate the population design (and the hidden truth) on the calibration and held-out trials."""
    from wrist_env import design
    from wrist_env.envs.task import task
    from wrist_env.participants import builtin

    designs = {"population": design.population()}
    if participant in builtin.BUILTIN:
        designs["truth"] = builtin.truth(participant)
    scores = {name: {m: _score(task(participant, m).evaluate(d)) for m in ("calibrate", "validate")}
              for name, d in designs.items()}
    return Reference(participant, scores["population"], scores.get("truth"))


def _rmse_array(rmse: dict | None) -> np.ndarray:
    """{bone: {DOF: value}} → (2, 6) in COST_BONES × DOF_NAMES order (NaN when missing)."""
    out = np.full((len(COST_BONES), len(DOF_NAMES)), np.nan)
    for b, bone in enumerate(COST_BONES):
        for d, dof in enumerate(DOF_NAMES):
            v = ((rmse or {}).get(bone) or {}).get(dof)
            out[b, d] = np.nan if v is None else v
    return out


def _q(values, q):
    values = np.asarray([v for v in values if v is not None and np.isfinite(v)], dtype=np.float64)
    return float(np.quantile(values, q)) if len(values) else np.nan


def _fmt(v, digits=3) -> str:
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "—"
    return f"{v:.{digits}g}" if abs(v) >= 1000 else f"{v:.{digits}f}"


def _md_table(frame: pd.DataFrame) -> str:
    cols = list(frame.columns)
    lines = ["| " + " | ".join(str(c) for c in cols) + " |", "|" + "---|" * len(cols)]
    for _, row in frame.iterrows():
        lines.append("| " + " | ".join(str(row[c]) for c in cols) + " |")
    return "\n".join(lines)


def _label(optimizer: str, budget: int, budgets: set) -> str:
    return optimizer if len(budgets) == 1 else f"{optimizer} (budget {budget})"


def load_runs(runs) -> tuple[pd.DataFrame, list[dict], int]:
    """(evaluations of finished cells, their summaries, number of unfinished cells) of a run log."""
    log = RunLog(runs)
    evals = log.read()
    summaries = log.summaries()
    finished = {(s["participant"], s["optimizer"], s["seed"], s["budget"]) for s in summaries}
    keys = list(zip(evals.participant, evals.optimizer, evals.seed, evals.budget))
    mask = np.array([k in finished for k in keys], dtype=bool)
    unfinished = len(set(keys) - finished)
    return evals[mask].reset_index(drop=True), summaries, unfinished


def _curves(evals: pd.DataFrame) -> dict:
    """{(participant, optimizer, seed, budget): best-so-far cost (nfev,)}."""
    out = {}
    for key, group in evals.groupby(["participant", "optimizer", "seed", "budget"], sort=True):
        out[key] = np.minimum.accumulate(group.sort_values("eval")["cost"].to_numpy())
    return out


def _hit(curve: np.ndarray, target: float) -> int | None:
    """Evaluations (1-based count) until the best-so-far cost is ≤ target; None if never."""
    idx = np.flatnonzero(curve <= target)
    return int(idx[0]) + 1 if len(idx) else None


def write_leaderboard(runs, out, *, references: dict | None = None, title: str | None = None) -> Path:
    """Write the leaderboards of the run log in `runs` into the folder `out`; returns out/README.md."""
    import matplotlib

    matplotlib.use("Agg")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    evals, summaries, unfinished = load_runs(runs)
    if not summaries:
        raise ValueError(f"{runs}: no finished benchmark cell in this run log")
    summaries = sorted(summaries, key=lambda s: (s["participant"], s["optimizer"], s["budget"], s["seed"]))
    budgets = {s["budget"] for s in summaries}
    participants = sorted({s["participant"] for s in summaries})
    labels = sorted({_label(s["optimizer"], s["budget"], budgets) for s in summaries})
    refs = dict(references or {})
    for p in participants:
        if p not in refs:
            refs[p] = reference(p)
    curves = _curves(evals)

    # targets
    target_rows = []
    for p in participants:
        r = refs[p]
        for name, base, factor in TARGETS:
            score = r.population if base == "population" else r.truth
            if score is not None:
                target_rows.append({"participant": p, "target": name, "reference": base, "factor": factor,
                                    "reference_cost": score["calibrate"]["cost"],
                                    "value": factor * score["calibrate"]["cost"]})
    targets = pd.DataFrame(target_rows)

    # one row per run
    run_rows = []
    for s in summaries:
        key = (s["participant"], s["optimizer"], s["seed"], s["budget"])
        curve = curves.get(key, np.array([s["best_cost"]]))
        row = {"participant": s["participant"], "calibrator": _label(s["optimizer"], s["budget"], budgets),
               "optimizer": s["optimizer"], "seed": s["seed"], "budget": s["budget"], "nfev": s["nfev"],
               "best_cost": s["best_cost"], "best_eval": s["best_eval"],
               "calibrate_cost": s["calibrate"]["cost"], "validate_cost": s["validate"]["cost"],
               "validate_failed": s["validate"]["failed"], "recovery_z": s["recovery_z"]}
        val = _rmse_array(s["validate"]["rmse"])
        row["validate_rmse_translation_mm"] = float(np.nanmean(val[:, :3])) if np.isfinite(val).any() else np.nan
        row["validate_rmse_rotation_deg"] = float(np.nanmean(val[:, 3:])) if np.isfinite(val).any() else np.nan
        for t in targets[targets.participant == s["participant"]].itertuples():
            row[f"evals_to_{t.target}"] = _hit(curve, t.value)
        run_rows.append(row)
    runs_frame = pd.DataFrame(run_rows)
    runs_frame.to_csv(out / "runs.csv", index=False, float_format="%.6g")
    targets.to_csv(out / "targets.csv", index=False, float_format="%.6g")

    best = _best_cost(runs_frame, refs, participants, labels)
    best.to_csv(out / "best_cost.csv", index=False, float_format="%.6g")
    ert = _evals_to_target(runs_frame, targets, participants, labels, curves)
    ert.to_csv(out / "evals_to_target.csv", index=False, float_format="%.6g")
    recovery = _recovery(runs_frame, summaries, participants, labels)
    recovery.to_csv(out / "recovery.csv", index=False, float_format="%.6g")
    heldout = _heldout(runs_frame, refs, participants, labels)
    heldout.to_csv(out / "heldout.csv", index=False, float_format="%.6g")
    chosen = _best_runs(summaries)
    table3 = _rmse_table(chosen, refs, participants, "calibrate")
    table4 = _rmse_table(chosen, refs, participants, "validate")
    table3.to_csv(out / "table3_rmse_calibrate.csv", index=False, float_format="%.4g")
    table4.to_csv(out / "table4_rmse_validate.csv", index=False, float_format="%.4g")
    improved = _dof_improved(summaries, chosen, refs, participants, labels, budgets)
    improved.to_csv(out / "dof_improved.csv", index=False, float_format="%.4g")

    colors = _colors(labels)
    _convergence_figure(out / "convergence.png", runs_frame, curves, refs, participants, labels, colors, budgets)
    _ecdf_figure(out / "ecdf.png", runs_frame, targets, curves, participants, labels, colors, budgets)

    readme = _readme(title, runs, summaries, unfinished, participants, labels, budgets, targets, best, ert, recovery,
                     heldout, table3, table4, improved, chosen)
    path = out / "README.md"
    path.write_text(readme)
    return path


def _best_cost(runs_frame, refs, participants, labels) -> pd.DataFrame:
    rows = []
    for p in participants:
        for label in labels:
            sub = runs_frame[(runs_frame.participant == p) & (runs_frame.calibrator == label)]
            if sub.empty:
                continue
            v = sub.best_cost.to_numpy()
            rows.append({"participant": p, "calibrator": label, "runs": len(v), "median": _q(v, 0.5),
                         "q25": _q(v, 0.25), "q75": _q(v, 0.75), "min": float(v.min()), "max": float(v.max()),
                         "population": refs[p].population["calibrate"]["cost"],
                         "truth": refs[p].truth["calibrate"]["cost"] if refs[p].truth else np.nan})
    return pd.DataFrame(rows)


def _evals_to_target(runs_frame, targets, participants, labels, curves) -> pd.DataFrame:
    """COCO's expected running time: evaluations spent over all runs (nfev for an unsolved run,
    the hitting count for a solved one) divided by the number of solved runs."""
    rows = []
    for t in targets.itertuples():
        for label in labels:
            sub = runs_frame[(runs_frame.participant == t.participant) & (runs_frame.calibrator == label)]
            if sub.empty:
                continue
            hits = [_hit(curves.get((r.participant, r.optimizer, r.seed, r.budget), np.array([r.best_cost])), t.value)
                    for r in sub.itertuples()]
            solved = [h for h in hits if h is not None]
            spent = sum(h if h is not None else r.nfev for h, r in zip(hits, sub.itertuples()))
            rows.append({"participant": t.participant, "target": t.target, "target_value": t.value,
                         "calibrator": label, "solved": len(solved), "runs": len(hits),
                         "ert": spent / len(solved) if solved else np.inf,
                         "median_evals_solved": float(np.median(solved)) if solved else np.nan})
    return pd.DataFrame(rows)


def _recovery(runs_frame, summaries, participants, labels) -> pd.DataFrame:
    population = {s["participant"]: s["recovery_z_population"] for s in summaries}
    rows = []
    for p in participants:
        for label in labels:
            sub = runs_frame[(runs_frame.participant == p) & (runs_frame.calibrator == label)]
            v = [x for x in sub.recovery_z if x is not None and np.isfinite(x)]
            if sub.empty or not v:
                continue
            rows.append({"participant": p, "calibrator": label, "runs": len(v), "median": _q(v, 0.5),
                         "q25": _q(v, 0.25), "q75": _q(v, 0.75), "population": population.get(p)})
    return pd.DataFrame(rows)


def _heldout(runs_frame, refs, participants, labels) -> pd.DataFrame:
    rows = []
    for p in participants:
        r = refs[p]
        for name, score in (("population", r.population), ("truth (hidden)", r.truth)):
            if score is None:
                continue
            val = _rmse_array(score["validate"]["rmse"])
            rows.append({"participant": p, "calibrator": name, "runs": 0, "cost_median": score["validate"]["cost"],
                         "cost_q25": np.nan, "cost_q75": np.nan, "failed": int(score["validate"]["failed"]),
                         "rmse_translation_mm": float(np.nanmean(val[:, :3])),
                         "rmse_rotation_deg": float(np.nanmean(val[:, 3:]))})
        for label in labels:
            sub = runs_frame[(runs_frame.participant == p) & (runs_frame.calibrator == label)]
            if sub.empty:
                continue
            v = sub.validate_cost.to_numpy()
            rows.append({"participant": p, "calibrator": label, "runs": len(v), "cost_median": _q(v, 0.5),
                         "cost_q25": _q(v, 0.25), "cost_q75": _q(v, 0.75), "failed": int(sub.validate_failed.sum()),
                         "rmse_translation_mm": _q(sub.validate_rmse_translation_mm, 0.5),
                         "rmse_rotation_deg": _q(sub.validate_rmse_rotation_deg, 0.5)})
    return pd.DataFrame(rows)


def _best_runs(summaries) -> dict:
    """Per participant, the run with the lowest calibration cost over all calibrators and seeds
    (ties: the first in participant, optimizer, budget, seed order) — as the preprint reports its one
    optimization per participant."""
    chosen = {}
    for s in summaries:
        p = s["participant"]
        if p not in chosen or s["best_cost"] < chosen[p]["best_cost"]:
            chosen[p] = s
    return chosen


def _rmse_table(chosen, refs, participants, trial) -> pd.DataFrame:
    rows = []
    for p in participants:
        r, s = refs[p], chosen[p]
        materials = [("Population", r.population[trial]["rmse"], "")]
        materials.append(("Calibrated", s[trial]["rmse"], f"{s['optimizer']} seed {s['seed']}"))
        if r.truth is not None:
            materials.append(("Truth (hidden)", r.truth[trial]["rmse"], ""))
        for b, bone in enumerate(COST_BONES):
            for material, rmse, run in materials:
                a = _rmse_array(rmse)
                row = {"participant": p, "bone": bone.capitalize(), "material": material}
                row.update({f"{dof} ({unit})": a[b, d] for d, (dof, unit) in enumerate(zip(DOF_NAMES, DOF_UNITS))})
                row["run"] = run
                rows.append(row)
    return pd.DataFrame(rows)


def _share_improved(pairs) -> float:
    """Percent of DOF entries with calibrated RMSE < population RMSE; pairs: [(population (2, 6), calibrated (2, 6))]."""
    better = total = 0
    for pop, cal in pairs:
        ok = np.isfinite(pop) & np.isfinite(cal)
        better += int(np.sum(cal[ok] < pop[ok]))
        total += int(np.sum(np.isfinite(pop)))
    return 100.0 * better / total if total else np.nan


def _dof_improved(summaries, chosen, refs, participants, labels, budgets) -> pd.DataFrame:
    rows = []

    def row(name, trial_pairs, runs):
        rows.append({"calibrated design": name, "runs": runs,
                     "calibrate_pct": trial_pairs["calibrate"], "validate_pct": trial_pairs["validate"],
                     "dof": 12 * len(participants)})

    row("best run per participant",
        {t: _share_improved([(_rmse_array(refs[p].population[t]["rmse"]), _rmse_array(chosen[p][t]["rmse"]))
                             for p in participants]) for t in ("calibrate", "validate")}, len(participants))
    for label in labels:
        shares = {"calibrate": [], "validate": []}
        mine = [s for s in summaries if _label(s["optimizer"], s["budget"], budgets) == label]
        for t in shares:  # every run counts: share over all its runs' DOF, pooled over participants
            shares[t] = _share_improved([(_rmse_array(refs[s["participant"]].population[t]["rmse"]),
                                          _rmse_array(s[t]["rmse"])) for s in mine])
        rows.append({"calibrated design": f"{label} (all runs)", "runs": len(mine),
                     "calibrate_pct": shares["calibrate"], "validate_pct": shares["validate"],
                     "dof": 12 * len(mine)})
    rows.append({"calibrated design": "preprint (Tables 3–4)", "runs": 3,
                 "calibrate_pct": PREPRINT_SHARE_IMPROVED["calibrate"],
                 "validate_pct": PREPRINT_SHARE_IMPROVED["validate"], "dof": 36})
    return pd.DataFrame(rows)


def _colors(labels) -> dict:
    import matplotlib

    cmap = matplotlib.colormaps["tab10"]
    return {label: cmap(i % 10) for i, label in enumerate(labels)}


def _convergence_figure(path, runs_frame, curves, refs, participants, labels, colors, budgets) -> None:
    import matplotlib.pyplot as plt

    n = len(participants)
    ncols = min(n, 3)
    nrows = -(-n // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.6 * ncols + 0.4, 4.0 * nrows + 0.5), squeeze=False,
                             constrained_layout=True)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    for ax, p in zip(axes.flat, participants):
        lows = []
        for label in labels:
            sub = runs_frame[(runs_frame.participant == p) & (runs_frame.calibrator == label)]
            cs = [curves[(r.participant, r.optimizer, r.seed, r.budget)] for r in sub.itertuples()
                  if (r.participant, r.optimizer, r.seed, r.budget) in curves]
            if not cs:
                continue
            length = max(len(c) for c in cs)
            stack = np.array([np.concatenate([c, np.full(length - len(c), c[-1])]) for c in cs])
            x = np.arange(1, length + 1)
            q25, med, q75 = np.quantile(stack, [0.25, 0.5, 0.75], axis=0)
            lows.append(float(q25.min()))
            ax.plot(x, med, color=colors[label], lw=1.8, label=f"{label} ({len(cs)} run{'s' if len(cs) > 1 else ''})")
            ax.fill_between(x, q25, q75, color=colors[label], alpha=0.18, lw=0)
        pop = refs[p].population["calibrate"]["cost"]
        ax.axhline(pop, color="0.35", ls="--", lw=1)
        ax.text(0.99, pop, "population", color="0.35", fontsize=8, ha="right", va="bottom",
                transform=ax.get_yaxis_transform())
        if refs[p].truth is not None:
            truth = refs[p].truth["calibrate"]["cost"]
            ax.axhline(truth, color="0.1", ls=":", lw=1.2)
            ax.text(0.01, truth, "hidden truth", color="0.1", fontsize=8, ha="left", va="top",
                    transform=ax.get_yaxis_transform())
        ax.set_yscale("log")
        low = min([refs[p].truth["calibrate"]["cost"] if refs[p].truth is not None else np.inf] + lows) * 0.85
        ax.set_ylim(low, 1.6 * pop)  # failed runs (cost 1000) would squash the interesting range
        _plain_log_ticks(ax.yaxis, subs=(1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 7.0))
        ax.set_title(f"{p}: calibration trial")
        ax.set_xlabel("evaluations")
        ax.grid(True, which="both", alpha=0.25)
        ax.set_xlim(1, max(budgets))
    for row in axes:
        row[0].set_ylabel("best cost so far (median, IQR band over seeds)")
    handles, names = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, names, loc="outside lower center", ncol=min(4, max(1, len(names))), fontsize=9, frameon=False)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _plain_log_ticks(axis, subs=(1.0, 2.0, 5.0)) -> None:
    """Log-axis ticks as plain numbers (1, 2, 5, 10, …) instead of 2 × 10^0."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    axis.set_major_locator(LogLocator(base=10, subs=subs))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def _ecdf_figure(path, runs_frame, targets, curves, participants, labels, colors, budgets) -> None:
    import matplotlib.pyplot as plt

    groups = [("all participants", participants)] + ([(p, [p]) for p in participants] if len(participants) > 1 else [])
    n = len(groups)
    ncols = n if n <= 3 else 2 if n == 4 else 3
    nrows = -(-n // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.6 * ncols + 0.4, 3.9 * nrows + 0.5), squeeze=False,
                             constrained_layout=True, sharey=True)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    top = max(budgets)
    grid = np.unique(np.round(np.geomspace(1, top, 200)).astype(int))
    for ax, (name, members) in zip(axes.flat, groups):
        n_targets = 0
        for label in labels:
            hits, pairs = [], 0
            for p in members:
                sub = runs_frame[(runs_frame.participant == p) & (runs_frame.calibrator == label)]
                ts = targets[targets.participant == p]
                for r in sub.itertuples():
                    curve = curves.get((r.participant, r.optimizer, r.seed, r.budget))
                    if curve is None:
                        continue
                    for t in ts.itertuples():
                        pairs += 1
                        h = _hit(curve, t.value)
                        if h is not None:
                            hits.append(h)
            if not pairs:
                continue
            n_targets = max(n_targets, len(targets[targets.participant.isin(members)]))
            hits = np.sort(np.array(hits))
            frac = np.searchsorted(hits, grid, side="right") / pairs
            ax.step(grid, frac, where="post", color=colors[label], lw=1.8, label=label)
        ax.set_xscale("log")
        ax.set_xlim(1, top)
        _plain_log_ticks(ax.xaxis)
        ax.set_ylim(0, 1.02)
        ax.set_xlabel("evaluations")
        ax.set_title(f"{name} ({n_targets} targets)")
        ax.grid(True, which="both", alpha=0.25)
    for row in axes:
        row[0].set_ylabel("fraction of (run, target) pairs solved")
        row[0].tick_params(labelleft=True)
    handles, names = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, names, loc="outside lower center", ncol=min(5, max(1, len(names))), fontsize=9, frameon=False)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _readme(title, runs, summaries, unfinished, participants, labels, budgets, targets, best, ert, recovery,
            heldout, table3, table4, improved, chosen) -> str:
    seeds = sorted({s["seed"] for s in summaries})
    n_evals = sum(s["nfev"] for s in summaries)
    lines = [f"# {title or 'Calibration benchmark leaderboard'}", "",
             f"Generated by `wrist-bench leaderboard --runs {runs}` from the run log: "
             f"{len(summaries)} finished runs ({len(participants)} participants × {len(labels)} calibrators × "
             f"seeds {seeds[0]}–{seeds[-1]}), budget {', '.join(str(b) for b in sorted(budgets))} evaluations, "
             f"{n_evals} evaluations in all" + (f"; {unfinished} unfinished cells left out" if unfinished else "") + ".",
             "",
             "Cost: the kinematic cost of the calibration (unresisted) trial (preprint 2.3.1.1; lower is better; "
             "a failed simulation costs 1000). Calibrators search the 22 material variables, ligaments intact. "
             "Medians and IQR (25th–75th percentile) are over seeds. The participants are synthetic; their "
             "hidden truth is the design the reference kinematics were made with (plus tracking noise and a finer "
             "model), so it is a good cost but not 0.", ""]

    lines += ["## Best cost at the budget", "", "Median [IQR] of each run's best calibration cost.", ""]
    wide = {"calibrator": labels}
    for p in participants:
        col = []
        for label in labels:
            r = best[(best.participant == p) & (best.calibrator == label)]
            col.append("—" if r.empty else f"{_fmt(r['median'].iloc[0])} [{_fmt(r.q25.iloc[0])}, {_fmt(r.q75.iloc[0])}]")
        wide[p] = col
    table = pd.DataFrame(wide)
    ref_rows = [{"calibrator": "*population design*",
                 **{p: _fmt(best[best.participant == p].population.iloc[0]) for p in participants}}]
    if best.truth.notna().any():
        ref_rows.append({"calibrator": "*hidden truth*",
                         **{p: _fmt(best[best.participant == p].truth.iloc[0]) for p in participants}})
    lines += [_md_table(pd.concat([table, pd.DataFrame(ref_rows)], ignore_index=True)), ""]
    lines += ["![convergence](convergence.png)", ""]

    lines += ["## Evaluations to reach cost targets", "",
              "Targets (the cost on the calibration trial): " + "; ".join(
                  f"{p}: " + ", ".join(f"{t.target} = {_fmt(t.value)}" for t in targets[targets.participant == p].itertuples())
                  for p in participants) + ". "
              "pop×f is f × the population design's cost, truth×1.1 is 1.1 × the hidden truth's cost. "
              "Each cell: runs that reached the target / runs, and COCO's expected running time (ERT: evaluations "
              "spent over all runs — the budget for an unsolved one — per solved run).", ""]
    for p in participants:
        ts = targets[targets.participant == p].target.tolist()
        wide = {"calibrator": labels}
        for t in ts:
            col = []
            for label in labels:
                r = ert[(ert.participant == p) & (ert.calibrator == label) & (ert.target == t)]
                if r.empty:
                    col.append("—")
                else:
                    r = r.iloc[0]
                    col.append(f"{r.solved}/{r.runs}" + (f", ERT {r.ert:.0f}" if np.isfinite(r.ert) else ""))
            wide[f"{p} {t}"] = col
        lines += [_md_table(pd.DataFrame(wide)), ""]
    lines += ["![ECDF](ecdf.png)", "",
              "ECDF in the style of COCO: for each calibrator, the fraction of all (run, target) pairs whose target "
              "the run's best-so-far cost had reached after a given number of evaluations.", ""]

    if not recovery.empty:
        lines += ["## Parameter recovery", "",
                  "RMS over the 22 materials of z(calibrated) − z(hidden truth), in Table 2 SD units; median [IQR] "
                  "over seeds. The population design's error is the baseline (the truth's own z-scores).", ""]
        wide = {"calibrator": labels}
        for p in participants:
            col = []
            for label in labels:
                r = recovery[(recovery.participant == p) & (recovery.calibrator == label)]
                col.append("—" if r.empty else f"{_fmt(r['median'].iloc[0])} [{_fmt(r.q25.iloc[0])}, {_fmt(r.q75.iloc[0])}]")
            wide[p] = col
        table = pd.DataFrame(wide)
        base = {"calibrator": "*population design*"}
        for p in participants:
            r = recovery[recovery.participant == p]
            base[p] = "—" if r.empty else _fmt(r.population.iloc[0])
        lines += [_md_table(pd.concat([table, pd.DataFrame([base])], ignore_index=True)), ""]

    lines += ["## Held-out resisted trial", "",
              "The calibrated design of each run (its best) simulated on the held-out resisted trial, never seen by "
              "the calibrator: cost median [IQR] over seeds; mean RMSE over the scaphoid's and lunate's translations "
              "(mm) and rotations (deg), median over seeds.", ""]
    hrows = []
    for p in participants:
        for r in heldout[heldout.participant == p].itertuples():
            cost = _fmt(r.cost_median) if r.runs == 0 else f"{_fmt(r.cost_median)} [{_fmt(r.cost_q25)}, {_fmt(r.cost_q75)}]"
            name = f"*{r.calibrator}*" if r.runs == 0 else r.calibrator
            hrows.append({"participant": p, "design": name, "cost": cost,
                          "RMSE transl. (mm)": _fmt(r.rmse_translation_mm), "RMSE rot. (deg)": _fmt(r.rmse_rotation_deg)})
    lines += [_md_table(pd.DataFrame(hrows)), ""]

    lines += ["## The preprint's Tables 3–4", "",
              "RMSE of the scaphoid and lunate DOF (mm, deg) of the population design and of the calibrated design "
              "— per participant the best run of all calibrators and seeds (lowest calibration cost; "
              + ", ".join(f"{p}: {s['optimizer']} seed {s['seed']}" for p, s in chosen.items())
              + ") — with the hidden truth for reference. Table 3: the calibration (unresisted) trial; "
              "Table 4: the held-out resisted trial.", ""]
    for name, table in (("Table 3 — calibration trial", table3), ("Table 4 — held-out resisted trial", table4)):
        shown = table.drop(columns=["run"]).copy()
        for c in shown.columns[3:]:
            shown[c] = [_fmt(v, 2) for v in shown[c]]
        lines += [f"**{name}**", "", _md_table(shown), ""]
    lines += ["**Share of DOF whose RMSE calibration lowered** (vs the population design; 12 DOF per participant "
              "and run)", ""]
    shown = improved.copy()
    shown["calibrate_pct"] = [_fmt(v, 1) + " %" for v in shown.calibrate_pct]
    shown["validate_pct"] = [_fmt(v, 1) + " %" for v in shown.validate_pct]
    shown = shown.rename(columns={"calibrate_pct": "calibration trial", "validate_pct": "held-out trial",
                                  "dof": "DOF counted"})
    lines += [_md_table(shown), ""]
    lines += ["CSV files: " + ", ".join(f"`{n}`" for n in (
        "best_cost.csv", "targets.csv", "evals_to_target.csv", "recovery.csv", "heldout.csv",
        "table3_rmse_calibrate.csv", "table4_rmse_validate.csv", "dof_improved.csv", "runs.csv")) + ".", ""]
    return "\n".join(lines)
