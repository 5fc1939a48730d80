"""The leaderboard's figures from a synthetic board (no simulation): one panel per participant (convergence) and
per participant plus all of them (ECDF); runs without a curve are left out."""

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from wrist_env.figures.leaderboard import colors, convergence_figure, ecdf_figure


def _board(participants, calibrators=("cmaes", "random"), seeds=(0, 1), budget=30, missing=()):
    rng = np.random.default_rng(0)
    rows, curves = [], {}
    for p in participants:
        for c in calibrators:
            for s in seeds:
                rows.append({"participant": p, "optimizer": c, "seed": s, "budget": budget, "calibrator": c})
                if (p, c, s) not in missing:
                    curves[(p, c, s, budget)] = np.minimum.accumulate(rng.uniform(1.0, 5.0, budget - s))
    refs = {
        p: SimpleNamespace(population={"calibrate": {"cost": 5.0}}, truth={"calibrate": {"cost": 0.9}} if i else None)
        for i, p in enumerate(participants)
    }
    targets = pd.DataFrame([{"participant": p, "value": v} for p in participants for v in np.geomspace(5.0, 1.0, 11)])
    return SimpleNamespace(
        runs_frame=pd.DataFrame(rows),
        curves=curves,
        refs=refs,
        participants=list(participants),
        labels=list(calibrators),
        budgets={budget},
        ecdf_targets=targets,
    )


@pytest.mark.parametrize("participants", [("P1",), ("P1", "P2", "P3", "U1")])
def test_the_figures_are_written(participants, tmp_path):
    board = _board(participants, missing={("P1", "random", 1)})
    palette = colors(board.labels)
    convergence_figure(tmp_path / "convergence.png", board, palette)
    ecdf_figure(tmp_path / "ecdf.png", board, palette)
    for name in ("convergence.png", "ecdf.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and (tmp_path / name).stat().st_size > 10_000


def test_colours_are_distinct_for_21_labels_then_cycle():
    palette = colors([f"c{i}" for i in range(22)])
    assert len(set(list(palette.values())[:21])) == 21 and palette["c21"] == palette["c0"]
