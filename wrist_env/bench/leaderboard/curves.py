"""What the leaderboard's figures draw, computed from its board: each participant's convergence curves over
its instances' hidden-truth costs and each group's (run, target) pairs solved (`figures.leaderboard` draws them)."""

from __future__ import annotations

import numpy as np

from wrist_env.bench.leaderboard.board import Leaderboard
from wrist_env.bench.leaderboard.reference import Reference
from wrist_env.bench.leaderboard.tables import hit, problem_of, runs_of
from wrist_env.figures.leaderboard import ConvergencePanel, EcdfPanel


def run_curves(board: Leaderboard, problem: str, label: str) -> list[np.ndarray]:
    """The best-so-far cost curves of one problem's runs with one calibrator (label), in the runs' order."""
    keys = [(r.problem, r.optimizer, r.seed, r.budget) for r in runs_of(board.runs_frame, problem, label).itertuples()]
    return [board.curves[k] for k in keys if k in board.curves]


def problems(board: Leaderboard, participant: str) -> list[str]:
    """The problems (instances) of one participant, in the board's order."""
    return [q for q in board.participants if problem_of(q)[0] == participant]


def scale(ref: Reference) -> float:
    """What a problem's costs are divided by to pool instances: its hidden truth's cost (the population's
    without a truth)."""
    return (ref.truth if ref.truth is not None else ref.population)["calibrate"]["cost"]


def convergence_panels(board: Leaderboard) -> list[ConvergencePanel]:
    """A panel per participant: its runs' curves over their instances' scale, per calibrator with a run, and
    the population design's median relative cost."""
    refs, panels = board.refs, []
    for p in board.subjects:
        members, curves = problems(board, p), {}
        for label in board.labels:
            cs = [c / scale(refs[q]) for q in members for c in run_curves(board, q, label)]
            if cs:
                curves[label] = tuple(cs)
        pop = float(np.median([refs[q].population["calibrate"]["cost"] / scale(refs[q]) for q in members]))
        truths = all(refs[q].truth is not None for q in members)
        panels.append(ConvergencePanel(p, len(members), curves, pop, truths))
    return panels


def ecdf_panels(board: Leaderboard) -> list[EcdfPanel]:
    """A panel of all problems, then (with more than one participant) one per participant pooling its
    instances: per calibrator, the evaluations at which each (run, target) pair was solved
    (`tables.ECDF_TARGETS` per problem, each instance's its own)."""
    targets = board.ecdf_targets
    groups = [("all problems", board.participants)]
    if len(board.subjects) > 1:
        groups += [(p, problems(board, p)) for p in board.subjects]
    panels = []
    for name, members in groups:
        n_targets, solved = 0, {}
        for label in board.labels:
            hits, pairs = [], 0
            for p in members:
                ts = targets[targets.problem == p]
                for curve in run_curves(board, p, label):
                    for t in ts.itertuples():
                        pairs += 1
                        h = hit(curve, t.value)
                        if h is not None:
                            hits.append(h)
            if not pairs:
                continue
            n_targets = max(n_targets, len(targets[targets.problem.isin(members)]))
            solved[label] = (np.sort(np.array(hits)), pairs)
        panels.append(EcdfPanel(name, n_targets, solved))
    return panels
