"""wrist-env: participant-specific wrist models as Gymnasium environments and an optimization benchmark.

Importing the package registers the Gymnasium ids of the built-in participants
(`wrist_env/Calibrate-P1-v0`, …); `register_participant(folder)` adds a user's.
"""

from wrist_env.envs import register_participant, registered_ids

__all__ = ["register_participant", "registered_ids"]
