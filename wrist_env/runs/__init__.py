"""What the benchmark and the Monte Carlo study share: one run store (`store`) and one executor (`executor`)."""

from wrist_env.runs.executor import Executor, executor
from wrist_env.runs.store import PartExistsError, RunStore, StoreBusyError

__all__ = ["Executor", "PartExistsError", "RunStore", "StoreBusyError", "executor"]
