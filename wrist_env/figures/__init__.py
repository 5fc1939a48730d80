"""Figures (matplotlib, PNG; a GIF): the model's geometry (`geometry`), its simulations (`simulation`), an animated sweep
(`animation`); the validation report (`validation`), the leaderboards (`leaderboard`), the Monte Carlo study
(`montecarlo`), sensitivity, identifiability and the posterior. The library never chooses a matplotlib backend."""

from wrist_env.figures.animation import animation_figure
from wrist_env.figures.draw import FIGURES
from wrist_env.figures.geometry import annotations_figure, model_figure
from wrist_env.figures.simulation import kinematics_figure, pressure_figure

__all__ = ["FIGURES", "animation_figure", "annotations_figure", "kinematics_figure", "model_figure", "pressure_figure"]
