"""Leaderboard tables that need no simulation: the COCO-style ECDF targets, the unsettled counts."""

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
            "problem": ["P1"] * 5,
            "calibrator": ["cmaes"] * 3 + ["random"] * 2,
            "best_cost": [1.0, 1.1, 1.2, 2.0, 2.1],
            "calibrate_unsettled_frames": [0, 3, 1, np.nan, 0],
            "unsettled_evals": [0.0, 0.1, 0.2, np.nan, 0.0],
        }
    )
    table = best_cost(frame, refs, ["P1"], ["cmaes", "random"]).set_index("calibrator")
    assert table.loc["cmaes", "unsettled"] == 2
    assert np.isnan(table.loc["random", "unsettled"])
    assert np.isclose(table.loc["cmaes", "unsettled_evals"], 0.1)  # the mean share over its runs
    assert np.isnan(table.loc["random", "unsettled_evals"])  # one run logged before it was recorded


def test_a_calibrated_design_reports_its_unsettled_frames():
    """`scoring._score` counts the frames whose hold ran out (info["settled"] False); None if failed."""
    from wrist_env.bench.scoring import _score

    info = {"rmse": {}, "error_p75": {}, "settled": np.array([True, False, True, False])}
    assert _score(SimpleNamespace(cost=1.5, failed=False, info=info))["unsettled_frames"] == 2
    assert _score(SimpleNamespace(cost=1000.0, failed=True, info=info))["unsettled_frames"] is None


def test_the_run_log_keeps_each_evaluations_unsettled_frames(tmp_path):
    """`unsettled` per logged evaluation (null where the run failed or the log predates it), and
    `unsettled_shares`: the share of a run's simulated evaluations with a frame that did not settle."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from wrist_env.bench.calibrate import unsettled_frames
    from wrist_env.bench.leaderboard.tables import unsettled_shares
    from wrist_env.bench.log import RunLog
    from wrist_env.bench.schema import SCHEMA, RunKey
    from wrist_env.runs.store import add_checksums

    log, key = RunLog(tmp_path), RunKey("P1", "random", 0, 4)
    info = {"settled": np.array([True, False, False])}
    runs = [SimpleNamespace(failed=False, info=info), SimpleNamespace(failed=True, info=info)]
    runs += [SimpleNamespace(failed=False, info={"settled": np.ones(3, bool)})] * 2
    counts = [unsettled_frames(e) for e in runs]
    assert counts == [2, None, 0, 0]
    x, rmse = np.zeros((4, 22)), np.zeros((4, 12))
    log.append(key, 0, 0, x, [1.0, 9.0, 2.0, 3.0], [False, True, False, False], rmse, unsettled=counts)
    rows = log.read()
    assert rows["unsettled"].tolist()[:1] == [2] and rows["unsettled"].isna().tolist() == [False, True, False, False]
    assert unsettled_shares(rows) == {("P1", "random", 0, 4): 1 / 3}  # 1 of the 3 that ran
    # a log written before the column existed reads as null, and its share is unknown (NaN)
    old = pa.schema([f for f in SCHEMA if f.name != "unsettled"])
    table = pa.Table.from_pandas(rows.drop(columns="unsettled"), schema=old, preserve_index=False)
    other = RunLog(tmp_path / "old")
    other.evals_dir.mkdir(parents=True)
    pq.write_table(table, other.evals_dir / f"cell-{key.name}-n000004.parquet")
    add_checksums(other.root)  # a log from before checksums, checksummed on request
    assert other.read()["unsettled"].isna().all()
    assert np.isnan(unsettled_shares(other.read())[("P1", "random", 0, 4)])
