"""Error hierarchy of wrist-env.

Every error names the rule that failed and the offending value; input errors
also name the file. Each class inherits a builtin so callers can catch either.
"""

__all__ = [
    "WristEnvError",
    "InputError",
    "MeshError",
    "TrialError",
    "ParticipantError",
    "DesignError",
    "BuildError",
    "StoreError",
    "DuplicateEvaluationError",
    "IncompleteCellError",
    "UsageError",
    "Interrupted",
]


class WristEnvError(Exception):
    """Base class of every wrist-env error."""


class InputError(WristEnvError, ValueError):
    """Bad user input: a file, a value or a shape that breaks a stated rule."""


class MeshError(InputError):
    """A bone mesh that cannot be used (units, watertightness, degeneracy, NaN)."""


class TrialError(InputError):
    """A kinematic trial that cannot be used (rotations, frame counts, bones, NaN)."""


class ParticipantError(InputError):
    """A participant folder or name that cannot be used."""


class DesignError(InputError):
    """A design vector or action outside its shape or bounds."""


class BuildError(WristEnvError, RuntimeError):
    """The participant build could not produce a valid model."""


class StoreError(InputError):
    """A saved file (a cached model, a run log) that is damaged, tampered with or not what it claims."""


class DuplicateEvaluationError(WristEnvError, RuntimeError):
    """An evaluation already in a benchmark's run log, logged again (`bench.RunLog.append` logs each once)."""


class IncompleteCellError(StoreError):
    """A benchmark cell whose summary says it finished, but whose evaluations are not all in the run log."""


class UsageError(InputError):
    """A command-line argument the command cannot take (exit status 2, like argparse's)."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during a long command, with a message saying what was saved and how to resume.

    The command line prints the message in one line and exits 130, the shell's code for SIGINT.
    """
