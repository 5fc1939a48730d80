"""The leaderboard's statistics without simulation: ERT and its bootstrapped interval, pooling over instances,
the ranking over problems (Friedman's test, Nemenyi's critical difference) and the Markdown they make."""

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from wrist_env.bench.leaderboard.readme import ert_cell, ranking_section, spread_cell
from wrist_env.bench.leaderboard.statistics import (
    AUTORANK_MIN_BLOCKS,
    ERT_PERCENTILES,
    ert,
    ert_interval,
    friedman_statistic,
    rank,
    ranking_words,
)
from wrist_env.bench.leaderboard.tables import evals_to_target, pooled_best_cost, problem_of


def test_ert_is_evaluations_spent_per_solved_run():
    # two solved at 10 and 20, one unsolved after its 50: (10 + 20 + 50) / 2
    assert ert([10, 20, 50], [True, True, False]) == 40.0
    assert ert([50, 50], [False, False]) == np.inf


def test_the_interval_collapses_when_every_run_solves_at_the_same_count():
    assert ert_interval([7, 7, 7, 7, 7], [True] * 5) == (7.0, 7.0)


def test_one_of_two_runs_unsolved_gives_an_open_upper_end():
    """Resamples of (solved at 10, unsolved after 15): both the solved run (ERT 10, a quarter of them), one each
    (25, a half) or both the unsolved (inf, a quarter): the 5th percentile is 10, the 95th is inf."""
    assert ERT_PERCENTILES == (5.0, 95.0)
    assert ert([10, 15], [True, False]) == 25.0
    assert ert_interval([10, 15], [True, False]) == (10.0, np.inf)


def test_a_rarely_unsolved_resample_leaves_the_upper_end_finite():
    """Nine runs solved at 10..90 and one unsolved after 100: a resample of ten without a solved run has
    probability 1e-10, so the 95th percentile is finite and the interval holds the ERT."""
    spent, solved = np.array([10, 20, 30, 40, 50, 60, 70, 80, 90, 100]), np.array([True] * 9 + [False])
    low, high = ert_interval(spent, solved)
    e = ert(spent, solved)
    assert np.isfinite(high) and low < e < high
    # every resampled ERT lies between the smallest and the largest a resample can have
    assert low >= 10.0 and high <= 100.0 * 10


def test_the_interval_is_deterministic_and_its_seed_matters():
    spent, solved = np.arange(1, 13) * 5, np.arange(12) % 3 != 0
    assert ert_interval(spent, solved) == ert_interval(spent, solved)
    assert ert_interval(spent, solved) != ert_interval(spent, solved, seed=1)


def test_mismatched_runs_are_refused():
    with pytest.raises(ValueError, match=r"spent \(3,\) and solved \(2,\)"):
        ert_interval([1, 2, 3], [True, False])


def _two_instance_runs():
    """P1's instances 0 and 1 (two seeds each) and P2's instance 0 (one seed), one calibrator; each problem its
    own target value, the hits already per run (NaN: never)."""
    rows = [
        ("P1", 0, "P1", 0, 12.0, 30, 3.0, 2.0),
        ("P1", 0, "P1", 1, np.nan, 30, 6.0, 2.0),
        ("P1", 1, "P1.i1", 1, 4.0, 30, 9.0, 6.0),
        ("P1", 1, "P1.i1", 2, 8.0, 30, 12.0, 6.0),
        ("P2", 0, "P2", 0, np.nan, 25, 5.0, 1.0),
    ]
    frame = pd.DataFrame(
        rows,
        columns=["participant", "instance", "problem", "seed", "evals_to_truth×1.1", "nfev", "best_cost", "truth_cost"],
    )
    frame["calibrator"] = "cmaes"
    frame["relative_cost"] = frame.best_cost / frame.truth_cost
    frame["population_cost"] = 4.0 * frame.truth_cost
    targets = pd.DataFrame({"problem": ["P1", "P1.i1", "P2"], "target": "truth×1.1", "value": [2.2, 6.6, 1.1]}).assign(
        participant=lambda t: [problem_of(p)[0] for p in t.problem]
    )
    return frame, targets


def test_ert_pools_a_participants_instances():
    frame, targets = _two_instance_runs()
    table = evals_to_target(frame, targets, ["P1", "P2"], ["cmaes"]).set_index("participant")
    p1 = table.loc["P1"]
    assert (p1.runs, p1.solved, p1.instances) == (4, 3, 2)
    assert p1.ert == pytest.approx((12 + 30 + 4 + 8) / 3)  # the unsolved run spends its 30
    assert p1.median_evals_solved == 8.0
    assert p1.ert_low <= p1.ert <= p1.ert_high
    p2 = table.loc["P2"]
    assert (p2.runs, p2.solved) == (1, 0) and p2.ert == np.inf and p2.ert_low == np.inf
    again = evals_to_target(frame, targets, ["P1", "P2"], ["cmaes"])
    pd.testing.assert_frame_equal(again.reset_index(drop=True), table.reset_index())  # same CSV twice


def test_best_cost_pools_as_a_ratio_to_each_instances_truth():
    frame, _ = _two_instance_runs()
    table = pooled_best_cost(frame, ["cmaes"]).set_index("participant")
    # P1's ratios: 3/2, 6/2, 9/6, 12/6 = 1.5, 3, 1.5, 2
    assert table.loc["P1", "median"] == pytest.approx(1.75) and table.loc["P1", "instances"] == 2
    assert table.loc["P1", "population"] == pytest.approx(4.0)
    assert table.loc["P2", "median"] == pytest.approx(5.0) and table.loc["P2", "runs"] == 1


def _blocks(scores: np.ndarray, names) -> pd.DataFrame:
    """A runs frame of one run per (problem, calibrator) with these scores (problems × calibrators)."""
    return pd.DataFrame(
        [
            {"problem": f"P1.i{b}", "calibrator": c, "relative_cost": scores[b, i]}
            for b in range(scores.shape[0])
            for i, c in enumerate(names)
        ]
    )


def test_friedmans_statistic_is_scipys_with_ties():
    scores = np.array([[1.0, 2.0, 2.0, 3.0], [1.5, 1.5, 1.5, 0.5], [3.0, 1.0, 2.0, 4.0], [2.0, 3.0, 1.0, 1.0]])
    scipy_value = stats.friedmanchisquare(*scores.T).statistic
    assert friedman_statistic(pd.DataFrame(scores)) == pytest.approx(scipy_value, rel=1e-12)


def test_the_ranking_tests_with_friedman_and_nemenyi():
    names = ["a", "b", "c", "d"]
    rng = np.random.default_rng(3)
    scores = rng.uniform(0, 0.3, (12, 4)) + np.arange(4)  # a < b < c < d on every problem
    ranking = rank(_blocks(scores, names), names)
    assert ranking.tested and ranking.blocks == 12 and not ranking.problems_left_out
    expected = stats.friedmanchisquare(*scores.T)
    assert ranking.statistic == pytest.approx(expected.statistic) and ranking.pvalue == pytest.approx(expected.pvalue)
    # Demšar 2006, Table 5(a): q_0.05 = 2.569 for four classifiers; CD = q sqrt(k (k + 1) / (6 N))
    assert ranking.cd == pytest.approx(2.569 * np.sqrt(4 * 5 / (6 * 12)), rel=1e-3)
    assert ranking.table.calibrator.tolist() == names and ranking.table.mean_rank.tolist() == [1.0, 2.0, 3.0, 4.0]
    # mean ranks one apart, CD 1.35: neighbours are not separable, two apart are
    assert ranking.groups == [["a", "b"], ["b", "c"], ["c", "d"]]
    assert ranking.table.not_separable_from.tolist() == ["b", "a; c", "b; d", "c"]
    assert "a, b: within the critical difference of each other" in ranking_words(ranking)
    assert "## Ranking over problems" in "\n".join(ranking_section(ranking, 12))


def test_a_problem_without_every_calibrator_is_left_out():
    names = ["a", "b", "c"]
    frame = _blocks(np.tile([1.0, 2.0, 3.0], (6, 1)), names)
    frame = frame[~((frame.problem == "P1.i5") & (frame.calibrator == "c"))]
    ranking = rank(frame, names)
    assert ranking.blocks == 5 and ranking.problems_left_out == ["P1.i5"] and ranking.tested


def test_too_few_problems_give_mean_ranks_and_say_the_test_needs_more():
    names = ["a", "b", "c"]
    scores = np.array([[1.0, 2.0, 3.0], [2.0, 1.0, 3.0], [1.0, 3.0, 2.0]])
    ranking = rank(_blocks(scores, names), names)
    assert not ranking.tested and ranking.result is None and np.isnan(ranking.pvalue)
    assert f"needs {AUTORANK_MIN_BLOCKS} or more" in ranking.reason
    assert ranking.table.set_index("calibrator").mean_rank.to_dict() == pytest.approx(
        {"a": 4 / 3, "b": 2.0, "c": 8 / 3}
    )
    text = "\n".join(ranking_section(ranking, 3))
    assert "No test: 3 problems" in text and "ranking.png" not in text


def test_two_calibrators_get_no_friedman_test():
    ranking = rank(_blocks(np.tile([1.0, 2.0], (6, 1)), ["a", "b"]), ["a", "b"])
    assert not ranking.tested and "compares 3 or more" in ranking.reason


def test_an_ert_cell_shows_the_interval_and_an_open_end():
    row = SimpleNamespace(solved=4, runs=5, ert=149.2, ert_low=92.0, ert_high=310.4)
    assert ert_cell(row) == "4/5, ERT 149 [92, 310]"
    assert ert_cell(SimpleNamespace(solved=1, runs=2, ert=25.0, ert_low=10.0, ert_high=np.inf)) == "1/2, ERT 25 [10, ∞]"
    assert ert_cell(SimpleNamespace(solved=0, runs=2, ert=np.inf, ert_low=np.inf, ert_high=np.inf)) == "0/2"


def test_a_single_run_shows_its_value_without_a_degenerate_interval():
    """The held-out table's cost: median [IQR] over two or more runs; one run (the default benchmark's one run per
    problem) or a reference design its value alone, not "[x, x]"."""
    assert spread_cell(1.5, 1.5, 1.5, 1) == "1.500"
    assert spread_cell(0.25, 0.25, 0.25, 0) == "0.250"
    assert spread_cell(1.5, 1.25, 2.0, 3) == "1.500 [1.250, 2.000]"
