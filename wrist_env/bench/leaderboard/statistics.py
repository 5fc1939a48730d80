"""The leaderboard's statistics: COCO's expected running time (ERT) with its bootstrapped interval, and the
ranking of calibrators over problems with Friedman's test and the Nemenyi post-hoc (via `autorank`).

ERT (Hansen, Auger, Ros, Finck, Pošík, "Comparing results of 31 algorithms from the black-box optimization
benchmarking BBOB-2009", GECCO 2010; the BBOB experimental-setup report): the evaluations spent over all
runs (the hitting count of a solved run, all its evaluations for an unsolved one) divided by the number of
solved runs; infinite when none solved. Its interval is COCO's bootstrap (Hansen, Auger, Ros, Mersmann,
Tušar, Brockhoff, "COCO: a platform for comparing continuous optimizers in a black-box setting", Optim.
Methods Softw. 36:114, 2021): resample the runs with replacement, the ERT of each resample, and the
`ERT_PERCENTILES` of those ERTs; a resample that solved nothing has an infinite ERT, so the upper end can
be open (∞).

The ranking (Demšar, "Statistical comparisons of classifiers over multiple data sets", JMLR 7:1, 2006;
the implementation: Herbold, "Autorank: a Python package for automated ranking of classifiers", JOSS
5(48):2173, 2020): each problem (participant, instance) is a block, a calibrator's score on it is its
best cost at the budget relative to the problem's hidden-truth cost (median over seeds), calibrators are
ranked per block (1 = lowest cost), Friedman's test asks whether the mean ranks differ more than chance,
and two calibrators whose mean ranks differ by less than Nemenyi's critical difference (CD) are ones the
data cannot separate.
"""

from __future__ import annotations

import contextlib
import io
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

ERT_RESAMPLES = 1000
"""Bootstrap resamples of the runs per ERT interval."""
ERT_PERCENTILES = (5.0, 95.0)
"""The percentiles of the resampled ERTs an interval spans: a 90 % interval, as COCO's."""
ERT_BOOTSTRAP_SEED = 20210101
"""The bootstrap's random seed: the same runs give the same interval (and the same CSVs) every time."""

RANKING_ALPHA = 0.05
"""Significance level of Friedman's test and of Nemenyi's critical difference."""
AUTORANK_MIN_BLOCKS = 5
"""`autorank` refuses fewer than five blocks (rows) of scores; with fewer the leaderboard gives the mean ranks
and says the test needs more problems."""
MIN_CALIBRATORS = 3
"""Friedman's test compares three or more calibrators (`scipy.stats.friedmanchisquare` refuses fewer)."""


def ert(spent: ArrayLike, solved: ArrayLike) -> float:
    """Expected running time of runs: sum of `spent` (evaluations: the hitting count of a solved run, nfev of an
    unsolved one) over the number of `solved` runs; inf if none solved."""
    spent, solved = np.asarray(spent, dtype=np.float64), np.asarray(solved, dtype=bool)
    return float(spent.sum() / solved.sum()) if solved.any() else np.inf


def ert_interval(
    spent: ArrayLike, solved: ArrayLike, *, resamples: int = ERT_RESAMPLES, seed: int = ERT_BOOTSTRAP_SEED
) -> tuple[float, float]:
    """COCO's bootstrapped interval of `ert(spent, solved)`: the `ERT_PERCENTILES` of the ERTs of `resamples`
    resamples of the runs drawn with replacement (an order statistic of the resampled ERTs, never an
    interpolation, so an unsolved resample's inf gives an open end, not NaN); (nan, nan) for no runs."""
    spent, solved = np.asarray(spent, dtype=np.float64), np.asarray(solved, dtype=bool)
    if spent.shape != solved.shape or spent.ndim != 1:
        raise ValueError(f"spent {spent.shape} and solved {solved.shape}: one value each per run")
    if not len(spent):
        return np.nan, np.nan
    pick = np.random.default_rng(seed).integers(0, len(spent), size=(resamples, len(spent)))
    hits = solved[pick].sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        erts = np.where(hits > 0, spent[pick].sum(axis=1) / hits, np.inf)
    low, high = np.percentile(erts, ERT_PERCENTILES, method="inverted_cdf")
    return float(low), float(high)


@dataclass(frozen=True)
class Ranking:
    """The calibrators ranked over problems (`rank`).

    table: one row per calibrator, best mean rank first: calibrator, mean_rank, median_score (median over
    problems of the relative best cost), score_ci_low/high (autorank's confidence interval, Bonferroni-corrected
    over the calibrators, of the scores' central tendency: of the median when its Shapiro-Wilk test finds a
    calibrator's scores not normal, else of the mean; NaN without the test), not_separable_from (the calibrators within the critical
    difference, "; "-joined); blocks: the problems ranked on; problems_left_out: problems without a score of
    every calibrator; statistic, pvalue: Friedman's chi-square and its p (NaN without the test); cd: Nemenyi's
    critical difference of mean ranks; groups: lists of calibrators within the CD of each other (cliques in
    mean-rank order, as the CD diagram's bars); reason: why there is no test ("" if there is); result:
    autorank's `RankResult` (for its CD diagram), None without the test; report: autorank's text report."""

    table: pd.DataFrame
    blocks: int
    problems_left_out: list
    statistic: float
    pvalue: float
    cd: float
    alpha: float
    groups: list
    reason: str
    result: object
    report: str

    @property
    def tested(self) -> bool:
        return not self.reason


def friedman_statistic(scores: pd.DataFrame) -> float:
    """Friedman's chi-square of a blocks × treatments table of scores (lower is better), mid-ranks for ties
    and the tie correction (Demšar 2006, eq. 1; as `scipy.stats.friedmanchisquare`)."""
    n, k = scores.shape
    ranks = scores.rank(axis=1).to_numpy()
    sums = ranks.sum(axis=0)
    ties = sum(float(np.sum(c**3 - c)) for c in (np.unique(row, return_counts=True)[1] for row in ranks))
    raw = 12.0 / (n * k * (k + 1)) * float(np.sum(sums**2)) - 3.0 * n * (k + 1)
    return raw / (1.0 - ties / (n * k * (k * k - 1)))


def score_blocks(runs_frame: pd.DataFrame, labels: list) -> tuple[pd.DataFrame, list]:
    """(problems × calibrators table of scores: median over seeds of `relative_cost`, only the problems every
    calibrator ran on; the problem names left out). Columns in `labels` order, rows in the runs' order."""
    medians = runs_frame.groupby(["problem", "calibrator"], sort=False).relative_cost.median()
    table = medians.unstack("calibrator").reindex(columns=labels)
    order = list(dict.fromkeys(runs_frame.problem))
    table = table.reindex(order)
    complete = table.notna().all(axis=1)
    return table[complete], [p for p in order if not complete[p]]


def _groups(names: list, mean_ranks: np.ndarray, cd: float) -> list[list]:
    """Maximal runs of calibrators, in mean-rank order, whose first and last differ by ≤ cd (so every pair
    within: the bars of the CD diagram, as `autorank`'s `get_sorted_rank_groups`)."""
    out, reach = [], -1
    for i in range(len(names)):
        j = max(j for j in range(i, len(names)) if mean_ranks[j] - mean_ranks[i] <= cd)
        if j > i and j > reach:
            out.append(names[i : j + 1])
            reach = j
    return out


def rank(runs_frame: pd.DataFrame, labels: list, alpha: float = RANKING_ALPHA) -> Ranking:
    """Rank the calibrators `labels` over the problems of `runs_frame` (columns problem, calibrator,
    relative_cost): Friedman's test and Nemenyi's critical difference by `autorank` (non-parametric mode
    forced: costs relative to the truth are not normal), or the mean ranks alone with `reason` saying why
    (fewer than `AUTORANK_MIN_BLOCKS` problems or `MIN_CALIBRATORS` calibrators)."""
    scores, left_out = score_blocks(runs_frame, labels)
    mean_ranks = scores.rank(axis=1).mean(axis=0) if len(scores) else pd.Series(np.nan, index=labels)
    order = sorted(labels, key=lambda c: (mean_ranks[c], c))
    reason = ""
    if len(labels) < MIN_CALIBRATORS:
        reason = f"{len(labels)} calibrators: Friedman's test compares {MIN_CALIBRATORS} or more"
    elif len(scores) < AUTORANK_MIN_BLOCKS:
        reason = (
            f"{len(scores)} problem{'s' if len(scores) != 1 else ''} with a score of every calibrator: the test "
            f"needs {AUTORANK_MIN_BLOCKS} or more (more instances of the participants)"
        )
    table = pd.DataFrame(
        {
            "calibrator": order,
            "mean_rank": [float(mean_ranks[c]) for c in order],
            "median_score": [float(scores[c].median()) if len(scores) else np.nan for c in order],
            "score_ci_low": np.nan,
            "score_ci_high": np.nan,
            "not_separable_from": "",
        }
    )
    if reason:
        return Ranking(table, len(scores), left_out, np.nan, np.nan, np.nan, alpha, [], reason, None, "")
    import autorank

    with contextlib.redirect_stdout(io.StringIO()), warnings.catch_warnings():  # it prints its tables
        warnings.simplefilter("ignore")
        result = autorank.autorank(
            scores.reset_index(drop=True), alpha=alpha, order="ascending", force_mode="nonparametric"
        )
    if result.omnibus != "friedman":
        raise RuntimeError(f"autorank ran {result.omnibus!r}, not Friedman's test: its version changed the API")
    report = io.StringIO()
    with contextlib.redirect_stdout(report), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        autorank.create_report(result)
    ranks = result.rankdf
    table["score_ci_low"] = [float(ranks.at[c, "ci_lower"]) for c in order]
    table["score_ci_high"] = [float(ranks.at[c, "ci_upper"]) for c in order]
    cd = float(result.cd)
    near = ["; ".join(o for o in order if o != c and abs(mean_ranks[o] - mean_ranks[c]) <= cd) for c in order]
    table["not_separable_from"] = near
    groups = _groups(order, np.array([mean_ranks[c] for c in order]), cd)
    return Ranking(
        table,
        len(scores),
        left_out,
        friedman_statistic(scores),
        float(result.pvalue),
        cd,
        alpha,
        groups,
        "",
        result,
        report.getvalue().strip(),
    )


def ranking_words(ranking: Ranking) -> str:
    """What the ranking says, in words: which calibrators the data cannot separate."""
    if not ranking.tested:
        return f"No test: {ranking.reason}. The mean ranks alone do not say which differences are chance."
    if ranking.pvalue >= ranking.alpha:
        return (
            f"Friedman's test does not reject that all calibrators rank alike (p ≥ {ranking.alpha:g}): the data "
            "cannot separate any of them."
        )
    if not ranking.groups:
        return "Every pair of calibrators differs by more than the critical difference: the data separates them all."
    alone = [c for c in ranking.table.calibrator if not any(c in g for g in ranking.groups)]
    words = [f"{', '.join(g)}: within the critical difference of each other" for g in ranking.groups]
    if alone:
        words.append(f"{', '.join(alone)}: separated from every other calibrator")
    return "The data cannot separate — " + "; ".join(words) + "."
