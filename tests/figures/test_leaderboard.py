"""The leaderboard's figures from a synthetic board (no simulation): one panel per participant pooling its instances
(convergence) and per participant plus all problems (ECDF), computed by `bench.leaderboard.curves`; runs without a
curve are left out; the ranking's critical-difference diagram."""

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from wrist_env.bench.leaderboard.curves import convergence_panels, ecdf_panels, problems
from wrist_env.bench.leaderboard.statistics import rank
from wrist_env.bench.leaderboard.tables import problem_of
from wrist_env.figures.leaderboard import colors, convergence_figure, ecdf_figure, ranking_figure


def _board(participants, calibrators=("cmaes", "random"), seeds=(0, 1), budget=30, missing=()):
    rng = np.random.default_rng(0)
    rows, curves = [], {}
    for p in participants:
        for c in calibrators:
            for s in seeds:
                rows.append(
                    {"participant": problem_of(p)[0], "problem": p, "optimizer": c, "seed": s, "budget": budget}
                    | {"calibrator": c}
                )
                if (p, c, s) not in missing:
                    curves[(p, c, s, budget)] = np.minimum.accumulate(rng.uniform(1.0, 5.0, budget - s))
    refs = {
        p: SimpleNamespace(population={"calibrate": {"cost": 5.0}}, truth={"calibrate": {"cost": 0.9}} if i else None)
        for i, p in enumerate(participants)
    }
    targets = pd.DataFrame([{"problem": p, "value": v} for p in participants for v in np.geomspace(5.0, 1.0, 11)])
    return SimpleNamespace(
        runs_frame=pd.DataFrame(rows),
        curves=curves,
        refs=refs,
        participants=list(participants),
        subjects=list(dict.fromkeys(problem_of(p)[0] for p in participants)),
        labels=list(calibrators),
        budgets={budget},
        ecdf_targets=targets,
    )


@pytest.mark.parametrize("participants", [("P1",), ("P1", "P2", "P3", "U1"), ("P1", "P1.i1", "P1.i2", "P2", "P2.i1")])
def test_the_figures_are_written(participants, tmp_path):
    board = _board(participants, missing={("P1", "random", 1)})
    palette = colors(board.labels)
    convergence_figure(tmp_path / "convergence.png", convergence_panels(board), palette, max(board.budgets))
    ecdf_figure(tmp_path / "ecdf.png", ecdf_panels(board), palette, max(board.budgets))
    for name in ("convergence.png", "ecdf.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and (tmp_path / name).stat().st_size > 10_000


def test_colours_are_distinct_for_21_labels_then_cycle():
    palette = colors([f"c{i}" for i in range(22)])
    assert len(set(list(palette.values())[:21])) == 21 and palette["c21"] == palette["c0"]


def test_a_participants_panel_pools_its_instances():
    board = _board(("P1", "P1.i1", "P1.i2", "P2", "P2.i1"))
    assert board.subjects == ["P1", "P2"]
    assert problems(board, "P1") == ["P1", "P1.i1", "P1.i2"] and problems(board, "P2") == ["P2", "P2.i1"]
    assert [(p.participant, p.instances) for p in convergence_panels(board)] == [("P1", 3), ("P2", 2)]
    assert [p.name for p in ecdf_panels(board)] == ["all problems", "P1", "P2"]


def test_a_run_without_a_curve_is_left_out_of_the_panels():
    board = _board(("P1",), missing={("P1", "random", 1)})
    (convergence,), (ecdf,) = convergence_panels(board), ecdf_panels(board)
    assert [len(convergence.curves[c]) for c in ("cmaes", "random")] == [2, 1]
    assert ecdf.solved["random"][1] == 11 and ecdf.targets == 11


def test_the_critical_difference_diagram_is_written(tmp_path):
    rng = np.random.default_rng(1)
    frame = pd.DataFrame(
        [
            {"problem": f"P{b}", "calibrator": c, "relative_cost": 1.0 + i + rng.uniform(0, 1.5)}
            for b in range(8)
            for i, c in enumerate(("cmaes", "random", "lhs"))
        ]
    )
    ranking = rank(frame, ["cmaes", "lhs", "random"])
    assert ranking.tested
    ranking_figure(tmp_path / "ranking.png", ranking.result, "test")
    assert (tmp_path / "ranking.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
