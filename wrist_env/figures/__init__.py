"""Figures (matplotlib, PNG): the model's geometry (`geometry`) and its simulations (`simulation`)."""

from wrist_env.figures.draw import FIGURES
from wrist_env.figures.geometry import annotations_figure, model_figure
from wrist_env.figures.simulation import kinematics_figure, pressure_figure

__all__ = ["FIGURES", "annotations_figure", "kinematics_figure", "model_figure", "pressure_figure"]
