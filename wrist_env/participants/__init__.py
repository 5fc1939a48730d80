"""Participants: the built-in ones (`builtin`), users' folders (`folder`, their bone meshes `bone_mesh`) and the
registry of models and trials (`registry`)."""

__all__ = ["BUILTIN"]

BUILTIN = ("P1", "P2", "P3")
"""The built-in participants (synthetic, the preprint's Table 1)."""
