"""Figures (matplotlib, PNG; a GIF): the model's geometry (`geometry`), its simulations (`simulation`), an animated sweep
(`animation`); the validation report (`validation`), the leaderboards (`leaderboard`), the Monte Carlo study
(`montecarlo`), sensitivity, identifiability and the posterior. The library never chooses a matplotlib backend.

Pictures take data: a figure draws the arrays, frames and frozen dataclasses it is given (a `Model`, a
`simulation.PressureFrame`, a `leaderboard.ConvergencePanel`, ...) and imports no study, participant, solver or
builder; the study or command that asks for it computes what is drawn (`tests/test_imports.py` checks it;
`validation.py` still reads a validation `Report` until the validation chain lands)."""

from wrist_env.figures.animation import animation_figure
from wrist_env.figures.draw import FIGURES
from wrist_env.figures.geometry import annotations_figure, model_figure
from wrist_env.figures.simulation import kinematics_figure, pressure_figure

__all__ = ["FIGURES", "animation_figure", "annotations_figure", "kinematics_figure", "model_figure", "pressure_figure"]
