"""Leaderboard tables that need no simulation: the COCO-style ECDF targets."""

from types import SimpleNamespace

import numpy as np

from wrist_env.bench.leaderboard.tables import ECDF_TARGETS, ecdf_targets, hit


def test_ecdf_targets_are_51_log_spaced_precisions_between_population_and_best_known():
    refs = {"P1": SimpleNamespace(population={"calibrate": {"cost": 4.0}})}
    curves = {("P1", "cmaes", 0, 300): np.array([4.5, 3.0, 2.0]), ("P1", "random", 0, 300): np.array([5.0, 1.0])}
    t = ecdf_targets(["P1"], refs, curves)
    assert len(t) == ECDF_TARGETS == 51
    gap = t.value.to_numpy() - 1.0  # best known cost 1.0
    assert np.isclose(gap[0], 3.0) and np.isclose(gap[-1], 3.0e-3)
    assert np.allclose(np.diff(np.log10(gap)), -3.0 / 50)  # five per decade over three decades
    # the run that reached the best known cost solves every target, the other only those above 2.0
    assert hit(curves[("P1", "random", 0, 300)], t.value.iloc[-1]) == 2
    assert sum(hit(curves[("P1", "cmaes", 0, 300)], v) is not None for v in t.value) == int(np.sum(t.value >= 2.0))


def test_a_participant_without_runs_gets_no_targets():
    refs = {"P2": SimpleNamespace(population={"calibrate": {"cost": 4.0}})}
    assert ecdf_targets(["P2"], refs, {}).empty


def test_best_cost_counts_runs_whose_calibrated_design_did_not_settle():
    """`unsettled` in best_cost.csv: the runs whose calibrated design has a frame that ran out of hold
    steps on the calibration trial; a failed design counts none; NaN for summaries logged before it."""
    import pandas as pd

    from wrist_env.bench.leaderboard.tables import best_cost

    refs = {"P1": SimpleNamespace(population={"calibrate": {"cost": 4.0}}, truth=None)}
    frame = pd.DataFrame(
        {
            "participant": ["P1"] * 5,
            "calibrator": ["cmaes"] * 3 + ["random"] * 2,
            "best_cost": [1.0, 1.1, 1.2, 2.0, 2.1],
            "calibrate_unsettled_frames": [0, 3, 1, np.nan, 0],
        }
    )
    table = best_cost(frame, refs, ["P1"], ["cmaes", "random"]).set_index("calibrator")
    assert table.loc["cmaes", "unsettled"] == 2
    assert np.isnan(table.loc["random", "unsettled"])


def test_a_calibrated_design_reports_its_unsettled_frames():
    """`calibrate._score` counts the frames whose hold ran out (info["settled"] False); None if failed."""
    from wrist_env.bench.calibrate import _score

    info = {"rmse": {}, "error_p75": {}, "settled": np.array([True, False, True, False])}
    assert _score(SimpleNamespace(cost=1.5, failed=False, info=info))["unsettled_frames"] == 2
    assert _score(SimpleNamespace(cost=1000.0, failed=True, info=info))["unsettled_frames"] is None
