"""A secant predictor for the next frame's equilibrium (Numba).

A quasi-static motion is a path of equilibria: from one frame to the next the free bones move on
from where the last two frames put them, in proportion to the capitate's move. So before a frame
the free bodies (scaphoid, lunate, the loaded capitate's centre) and the membrane's free nodes are
put where the line through the last two frames' equilibria says they will be (the secant predictor
of numerical continuation), their velocities zeroed, and the hold starts from there. The predictor
only chooses the starting point of the hold: the frame still ends at equilibrium
(`stopping.converged`), so a poor prediction costs steps, not accuracy, unless the path has more
than one equilibrium (a design whose answer depends on its path; `experiments/verification/solver_accuracy.py`).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from wrist_env.model import CAPITATE, FREE
from wrist_env.solver.arrays import LOADED
from wrist_env.solver.rigid import LEVER_MM, copy_into, rotate_in_place, rotvec_between

MAX_RATIO = 2.0
"""The most the last frame's change is extrapolated by (a frame whose capitate moves more than twice the
last one's is predicted as twice)."""

History = namedtuple("History", ["rotation", "centre", "nodes", "move", "count"])
"""The last two equilibria: rotations (2, n_bodies, 3, 3), centres (2, n_bodies, 3) mm, membrane nodes
(2, M, 3) mm, the capitate's move into each (2,) mm (`capitate_move`), and how many are stored (1,)."""


@njit(cache=True)
def history(n_bodies, nodes):
    """An empty `History`."""
    return History(
        np.zeros((2, n_bodies, 3, 3)),
        np.zeros((2, n_bodies, 3)),
        np.zeros((2,) + nodes.shape),
        np.zeros(2),
        np.zeros(1, np.int64),
    )


@njit(cache=True, error_model="numpy")
def capitate_move(axis, shift):
    """The size (mm) of a capitate move of rotation vector `axis` (rad) and translation `shift` (mm)."""
    return LEVER_MM * np.sqrt(axis[0] ** 2 + axis[1] ** 2 + axis[2] ** 2) + np.sqrt(
        shift[0] ** 2 + shift[1] ** 2 + shift[2] ** 2
    )


@njit(cache=True, error_model="numpy")
def record(h, R, x, nodes, move):
    """Store the equilibrium (R, x, nodes) reached by a stage whose capitate moved `move` (mm)."""
    copy_into(h.rotation[0], h.rotation[1])
    copy_into(h.centre[0], h.centre[1])
    copy_into(h.nodes[0], h.nodes[1])
    h.move[0] = h.move[1]
    copy_into(h.rotation[1], R)
    copy_into(h.centre[1], x)
    copy_into(h.nodes[1], nodes)
    h.move[1] = move
    h.count[0] = min(h.count[0] + 1, 2)


@njit(cache=True, error_model="numpy")
def predict(h, state, mem, st, move):
    """Put the free bodies and nodes of `state` (`step.State`) where the secant through the last two
    equilibria (`History` h) says the next stage, whose capitate moves `move` (mm), ends; velocities
    zeroed. False (nothing changed) without two equilibria or when the last stage's capitate did not move;
    mem, st: the `arrays.Membrane` (its nodes' bones) and `arrays.Settings` (the driver)."""
    R, x, v, w, nodes, nv = state
    if h.count[0] < 2 or not h.move[1] > 1e-9:
        return False
    ratio = min(move / h.move[1], MAX_RATIO)
    for b in FREE:
        turn = rotvec_between(h.rotation[1, b], h.rotation[0, b])
        copy_into(R[b], h.rotation[1, b])
        rotate_in_place(R[b], ratio * turn[0], ratio * turn[1], ratio * turn[2])
        for k in range(3):
            x[b, k] = h.centre[1, b, k] + ratio * (h.centre[1, b, k] - h.centre[0, b, k])
    if st.driver == LOADED:
        for k in range(3):
            x[CAPITATE, k] = h.centre[1, CAPITATE, k] + ratio * (h.centre[1, CAPITATE, k] - h.centre[0, CAPITATE, k])
    for i in range(nodes.shape[0]):
        if mem.bone[i] < 0:
            for k in range(3):
                nodes[i, k] = h.nodes[1, i, k] + ratio * (h.nodes[1, i, k] - h.nodes[0, i, k])
    v[:] = 0.0
    w[:] = 0.0
    nv[:] = 0.0
    return True
