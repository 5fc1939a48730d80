"""The leaderboard's README.md: every table in Markdown, with the figures."""

from __future__ import annotations

import numpy as np
import pandas as pd

from wrist_env.bench.leaderboard.board import CSV_FILES, Leaderboard
from wrist_env.bench.leaderboard.statistics import (
    ERT_PERCENTILES,
    ERT_RESAMPLES,
    Ranking,
    ranking_words,
)
from wrist_env.bench.leaderboard.tables import ECDF_TARGETS, problem_of


def fmt(v: float | None, digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "—"
    return f"{v:.{digits}g}" if abs(v) >= 1000 else f"{v:.{digits}f}"


def md_table(frame: pd.DataFrame) -> str:
    cols = list(frame.columns)
    lines = ["| " + " | ".join(str(c) for c in cols) + " |", "|" + "---|" * len(cols)]
    for _, row in frame.iterrows():
        lines.append("| " + " | ".join(str(row[c]) for c in cols) + " |")
    return "\n".join(lines)


def _wide(frame: pd.DataFrame, columns: dict[str, pd.Series], labels: list, cell) -> pd.DataFrame:
    """A column of labels (calibrators), then one per entry of `columns` (its title → a mask of `frame`'s rows):
    `cell` of the label's first row there, or — where it has none."""
    wide = {"calibrator": labels}
    for title, mask in columns.items():
        rows = frame[mask]
        col = []
        for label in labels:
            r = rows[rows.calibrator == label]
            col.append("—" if r.empty else cell(r.iloc[0]))
        wide[title] = col
    return pd.DataFrame(wide)


def _median_iqr(frame: pd.DataFrame, participants: list, labels: list) -> pd.DataFrame:
    """A column of labels (calibrators), then one per participant: its row's "median [q25, q75]" in `frame`, or —."""
    columns = {p: frame.participant == p for p in participants}
    return _wide(frame, columns, labels, lambda r: f"{fmt(r['median'])} [{fmt(r.q25)}, {fmt(r.q75)}]")


def spread_cell(median: float, q25: float, q75: float, runs: int) -> str:
    """A table cell "median [q25, q75]" over `runs` runs; one run (or none: a reference design) has no spread to
    show, so its value alone, not "[x, x]"."""
    return fmt(median) if runs < 2 else f"{fmt(median)} [{fmt(q25)}, {fmt(q75)}]"


def ert_cell(r) -> str:
    """An `evals_to_target.csv` row as a table cell: "solved/runs, ERT e [low, high]" (∞: an open end)."""

    def end(v: float) -> str:
        return "∞" if np.isinf(v) else f"{v:.0f}"

    cell = f"{r.solved}/{r.runs}"
    return cell + (f", ERT {r.ert:.0f} [{end(r.ert_low)}, {end(r.ert_high)}]" if np.isfinite(r.ert) else "")


def ranking_title(ranking: Ranking) -> str:
    """The critical-difference diagram's title: the test, its p and the critical difference."""
    verdict = "rejects" if ranking.pvalue < ranking.alpha else "does not reject"
    return (
        f"Mean rank over {ranking.blocks} problems (1 = lowest cost); Friedman p = {ranking.pvalue:.3g} "
        f"({verdict} equal ranks at {ranking.alpha:g}); Nemenyi CD = {ranking.cd:.2f}"
    )


def ranking_section(ranking: Ranking, n_problems: int) -> list[str]:
    """The Markdown section of the ranking over problems: the test, the table of mean ranks, the CD diagram."""
    lines = [
        "## Ranking over problems",
        "",
        "Each problem (a participant's instance) is a block; a calibrator's score on it is its best cost at the "
        "budget relative to the problem's hidden-truth cost, the median over seeds; the calibrators are ranked "
        "per problem (1 = lowest cost) and the ranks averaged. Friedman's test asks whether the mean ranks differ "
        "more than chance would make them; the Nemenyi post-hoc's critical difference (CD) is how far apart two "
        "mean ranks must be for the data to separate the two calibrators (Demšar 2006; computed by `autorank`, "
        "Herbold 2020, non-parametric mode).",
        "",
    ]
    if ranking.problems_left_out:
        lines += [
            f"Left out (not every calibrator ran on them): {', '.join(ranking.problems_left_out)} "
            f"of {n_problems} problems.",
            "",
        ]
    if ranking.tested:
        lines += [
            f"Friedman's χ² = {ranking.statistic:.2f} over {ranking.blocks} problems and {len(ranking.table)} "
            f"calibrators, p = {ranking.pvalue:.3g}; critical difference (α = {ranking.alpha:g}) = {ranking.cd:.2f} "
            "mean ranks.",
            "",
        ]
    lines += [ranking_words(ranking), ""]
    shown = pd.DataFrame(
        {
            "calibrator": ranking.table.calibrator,
            "mean rank": [fmt(v, 2) for v in ranking.table.mean_rank],
            "median best / truth": [fmt(v) for v in ranking.table.median_score],
        }
    )
    if ranking.tested:
        shown["not separable from"] = [v or "—" for v in ranking.table.not_separable_from]
    lines += [md_table(shown), ""]
    if ranking.tested:
        lines += [
            "![ranking](ranking.png)",
            "",
            "Critical-difference diagram (`autorank`): the axis is the mean rank, 1 (the best) at the right; each "
            "calibrator's name hangs from its mean rank; the segment marked CD above the axis is the critical "
            "difference, and a thick bar joins calibrators whose mean ranks lie within it of each other — the "
            "data cannot separate them. The title gives Friedman's p: when it is above α the diagram is drawn "
            "anyway but no difference in it is a finding. `autorank`'s own report of the analysis (its normality "
            "and homogeneity checks, medians and mean ranks): `ranking_report.txt`.",
            "",
        ]
    return lines


def readme(board: Leaderboard, title: str | None = None) -> str:
    """The leaderboard's README.md text (Markdown)."""
    b = board
    runs, summaries, unfinished, participants, labels, budgets = (
        b.runs,
        b.summaries,
        b.unfinished,
        b.participants,
        b.labels,
        b.budgets,
    )
    targets, best, ert, heldout = b.targets, b.best, b.ert, b.heldout
    table3, table4, improved, chosen = b.table3, b.table4, b.improved, b.chosen
    subjects = b.subjects
    seeds = sorted({s["seed"] for s in summaries})
    n_evals = sum(s["nfev"] for s in summaries)
    instances = sorted({s["instance"] for s in summaries})
    problems = (
        f"{len(participants)} participants"
        if instances == [0]
        else f"{len(participants)} problems — instances {', '.join(str(k) for k in instances)} of "
        f"{len(subjects)} participants —"
    )
    seeding = f"seeds {seeds[0]}–{seeds[-1]}" if len(seeds) > 1 else f"seed {seeds[0]}"
    lines = [
        f"# {title or 'Calibration benchmark leaderboard'}",
        "",
        f"Generated by `wrist-bench leaderboard --runs {runs}` from the run log: "
        f"{len(summaries)} finished runs ({problems} × {len(labels)} calibrators, {seeding}), "
        f"budget {', '.join(str(b) for b in sorted(budgets))} evaluations, "
        f"{n_evals} evaluations in all" + (f"; {unfinished} unfinished cells left out" if unfinished else "") + ".",
        "",
        "Cost: the kinematic cost of the calibration (unresisted) trial (preprint 2.3.1.1; lower is better; "
        "a failed simulation costs 1000). Calibrators search the 22 material variables, ligaments intact. "
        "The participants are synthetic; their hidden truth is the design the reference kinematics were made "
        "with (plus tracking noise and a finer model), so it is a good cost but not 0. A problem is a "
        "participant's instance (instance 0: its shipped truth and trials; instance k ≥ 1: a truth drawn from "
        "the population prior with its own trials, named <participant>.i<k> in the CSVs); the tables and panels "
        "below are per participant, pooling the runs of all its instances and seeds — medians and IQR "
        "(25th–75th percentile) are over those runs; the CSVs keep each problem's own numbers.",
        "",
    ]

    lines += [
        "## Best cost at the budget",
        "",
        "Median [IQR] of each run's best calibration cost divided by its instance's hidden-truth cost (1 = as "
        "good as the truth; raw costs per problem in `best_cost.csv`).",
        "",
    ]
    pooled = b.best_pooled
    table = _median_iqr(pooled, subjects, labels)
    ref_rows = [
        {
            "calibrator": "*population design*"
            + (" (median over instances)" if len(participants) > len(subjects) else ""),
            **{p: fmt(pooled[pooled.participant == p].population.iloc[0]) for p in subjects},
        }
    ]
    lines += [md_table(pd.concat([table, pd.DataFrame(ref_rows)], ignore_index=True)), ""]
    if best.unsettled.notna().all():
        flagged = best[best.unsettled > 0]
        which = "; ".join(
            f"{r.calibrator} on {r.problem}: {int(r.unsettled)} of {r.runs}" for r in flagged.itertuples()
        )
        lines += [
            "Calibrated designs with a frame whose hold ran out before equilibrium (`unsettled` in "
            "`best_cost.csv`: that frame's pose is where the solver stopped, not a balanced one): "
            + (which or "none")
            + ".",
            "",
        ]
    if best.unsettled_evals.notna().all():
        worst = best.loc[best.unsettled_evals.idxmax()]
        lines += [
            "Evaluations on the way with such a frame (`unsettled_evals`, a share of each calibrator's "
            f"evaluations): at most {worst.unsettled_evals:.1%} ({worst.calibrator} on {worst.problem}).",
            "",
        ]
    lines += ["![convergence](convergence.png)", ""]

    one_each = all(len(set(targets.problem[targets.participant == p])) == 1 for p in subjects)
    values = (
        "; ".join(
            f"{p}: " + ", ".join(f"{t.target} = {fmt(t.value)}" for t in targets[targets.participant == p].itertuples())
            for p in subjects
        )
        if one_each
        else "each instance's own, in `targets.csv`"
    )
    low, high = ERT_PERCENTILES
    lines += [
        "## Evaluations to reach cost targets",
        "",
        f"Targets (the cost on the calibration trial): {values}. "
        "pop×f is f × the population design's cost, truth×1.1 is 1.1 × the hidden truth's cost — of the run's "
        "own instance, so runs on different instances pool. "
        "Each cell: runs that reached the target / runs, then COCO's expected running time (ERT: evaluations "
        "spent over all runs — all of an unsolved run's — per solved run; Hansen et al., GECCO 2010) and its "
        f"bootstrapped {high - low:.0f} % interval: the {low:g}th and {high:g}th percentiles of the ERTs of "
        f"{ERT_RESAMPLES:,} resamples of the runs drawn with replacement (COCO's method, Hansen et al., Optim. "
        "Methods Softw. 2021); ∞: resamples that solved nothing, an open upper end.",
        "",
    ]
    for p in subjects:
        ts = list(dict.fromkeys(ert.target[ert.participant == p]))
        columns = {f"{p} {t}": (ert.participant == p) & (ert.target == t) for t in ts}
        lines += [md_table(_wide(ert, columns, labels, ert_cell)), ""]
    lines += [
        "![ECDF](ecdf.png)",
        "",
        "ECDF in the style of COCO: for each calibrator, the fraction of all (run, target) pairs whose target "
        "the run's best-so-far cost had reached after a given number of evaluations, pooled over a "
        f"participant's instances (and over all problems in the first panel); {ECDF_TARGETS} targets per problem, "
        "log-spaced from its population design's cost down to a thousandth of its distance to the best cost any "
        "run on it reached (`ecdf_targets.csv`).",
        "",
    ]
    lines += ranking_section(b.ranking, len(participants))

    recovery = b.recovery_pooled
    if not recovery.empty:
        lines += [
            "## Parameter recovery",
            "",
            "RMS over the 22 materials of z(calibrated) − z(hidden truth), in Table 2 SD units (the same scale on "
            "every instance); median [IQR] over all runs of the participant's instances. The population design's "
            "error is the baseline (the truth's own z-scores; median over instances). Per problem: `recovery.csv`.",
            "",
        ]
        table = _median_iqr(recovery, subjects, labels)
        base = {"calibrator": "*population design*"}
        for p in subjects:
            r = recovery[recovery.participant == p]
            base[p] = "—" if r.empty else fmt(r.population.iloc[0])
        lines += [md_table(pd.concat([table, pd.DataFrame([base])], ignore_index=True)), ""]

    shipped = [q for q in participants if problem_of(q)[1] == 0] or participants
    on = (
        ""
        if shipped == participants
        else " Shown for the shipped problems (instance 0), as the preprint's; every problem in the CSV files."
    )
    lines += [
        "## Held-out resisted trial",
        "",
        "The calibrated design of each run (its best) simulated on the held-out resisted trial, never seen by "
        "the calibrator: cost median [IQR] over its runs of the problem (one run: its cost); mean RMSE over the "
        "scaphoid's and lunate's translations (mm) and rotations (deg), median over the runs." + on,
        "",
    ]
    hrows = []
    for p in shipped:
        for r in heldout[heldout.problem == p].itertuples():
            cost = spread_cell(r.cost_median, r.cost_q25, r.cost_q75, r.runs)
            name = f"*{r.calibrator}*" if r.runs == 0 else r.calibrator
            hrows.append(
                {
                    "participant": p,
                    "design": name,
                    "cost": cost,
                    "RMSE transl. (mm)": fmt(r.rmse_translation_mm),
                    "RMSE rot. (deg)": fmt(r.rmse_rotation_deg),
                }
            )
    lines += [md_table(pd.DataFrame(hrows)), ""]

    lines += [
        "## The preprint's Tables 3–4",
        "",
        "RMSE of the scaphoid and lunate DOF (mm, deg) of the population design and of the calibrated design "
        "— per participant the best run of all calibrators and seeds (lowest calibration cost; "
        + ", ".join(f"{p}: {s['optimizer']} seed {s['seed']}" for p, s in chosen.items() if p in shipped)
        + ") — with the hidden truth for reference. Table 3: the calibration (unresisted) trial; "
        "Table 4: the held-out resisted trial." + on,
        "",
    ]
    for name, table in (("Table 3 — calibration trial", table3), ("Table 4 — held-out resisted trial", table4)):
        shown = table[table.problem.isin(shipped)].drop(columns=["run", "instance", "problem"])
        for c in shown.columns[3:]:
            shown[c] = [fmt(v, 2) for v in shown[c]]
        lines += [f"**{name}**", "", md_table(shown), ""]
    lines += [
        "**Share of DOF whose RMSE calibration lowered** (vs the population design; 12 DOF per participant and run)",
        "",
    ]
    shown = improved.copy()
    shown["calibrate_pct"] = [fmt(v, 1) + " %" for v in shown.calibrate_pct]
    shown["validate_pct"] = [fmt(v, 1) + " %" for v in shown.validate_pct]
    shown = shown.rename(
        columns={"calibrate_pct": "calibration trial", "validate_pct": "held-out trial", "dof": "DOF counted"}
    )
    lines += [md_table(shown), ""]
    lines += ["CSV files: " + ", ".join(f"`{n}`" for n in CSV_FILES) + ".", ""]
    return "\n".join(lines)
