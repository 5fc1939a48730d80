"""wrist-env: participant-specific wrist models as Gymnasium environments and an optimization benchmark.

The Gymnasium ids of the built-in participants (`wrist_env/Calibrate-P1-v0`, …) are registered as soon as
both this package and `gymnasium` are imported, in either order (a post-import hook: importing
`wrist_env.design` or `wrist_env.cost` alone imports neither Gymnasium nor the model builder);
`register_participant(folder)` adds a user's. Importing it points Numba's cache at the folder of the
kernels' current sources (`kernel_cache`).
"""

import wrapt

from wrist_env import kernel_cache

kernel_cache.configure()  # before any kernel is defined: Numba's cache folder follows the kernels' sources

from wrist_env.participants import BUILTIN  # noqa: E402

__all__ = ["register_participant", "registered_ids"]


def _register_builtin_ids(gymnasium) -> None:
    from wrist_env.envs.ids import register_ids  # only once Gymnasium is imported: the ids live in its registry

    for name in BUILTIN:
        register_ids(gymnasium, name)


wrapt.register_post_import_hook(_register_builtin_ids, "gymnasium")


def __getattr__(name: str):
    """`register_participant` and `registered_ids`, from `wrist_env.envs` (Gymnasium) on first use."""
    if name in __all__:
        from wrist_env import envs  # the Gymnasium layer, imported on first use

        return getattr(envs, name)
    raise AttributeError(f"module 'wrist_env' has no attribute {name!r}")
