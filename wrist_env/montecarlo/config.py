"""What a Monte Carlo study is: the settings that decide every run (`StudyConfig`: participants, n
successful runs each, seed, tear probability, exclusion threshold in MPa, load direction), and the
error raised by a study that cannot run (`StudyError`)."""

from __future__ import annotations

from dataclasses import dataclass

from wrist_env.errors import WristEnvError
from wrist_env.ligaments import INJURABLE
from wrist_env.limits import MAX_RUNS, MAX_SEED, check_int, check_unique
from wrist_env.solver.settings import DEFAULT_LOADS, LOAD_DIRECTIONS

VERSION = 1
TEAR_PROBABILITY = 0.3
"""Chance that each injurable ligament is torn in a Monte Carlo run (preprint 2.3.2)."""
EXCLUDE_ABOVE_MPA = 16.5
"""A run is excluded when its radioscaphoid mean pressure exceeds this (MPa) at any frame of the sweep
(preprint 2.3.2; how we read it: `sampler`)."""
MIN_FIT_RUNS = 2 + len(INJURABLE)
"""Runs the report's Table 5 fit needs at least (`montecarlo-report --max-runs`, `stats.subsample_runs`,
`stats.MIN_RUNS_TABLE5`): its intercept and five tear indicators are constant within a run, so they are told
apart only between runs, and one run more leaves the variance between runs to estimate; fewer is singular
whatever runs are drawn (more can still be, when a tear is in all or none of them: `stats` names it)."""
FIT_RUNS_WHY = (
    f"Table 5's intercept, {len(INJURABLE)} tear indicators and the variance between runs need {MIN_FIT_RUNS} runs"
)
"""Why `MIN_FIT_RUNS`, in the one line that refuses fewer."""


class StudyError(WristEnvError):
    """A study that cannot run: a folder holding another study, a duplicated run, no successes.

    Also raised for a `StudyConfig` that cannot be a study (no participant, a tear probability outside [0, 1],
    an unknown load direction) and when a participant's runs reach the attempt limit; the message names the
    folder or part and the rule.
    """


@dataclass(frozen=True)
class StudyConfig:
    """What a study is: these decide every run (how it is run does not).

    Parameters
    ----------
    participants : tuple of str, length n_participants
        The participants, each named once (a list is stored as a tuple).
    n : int
        Successful runs per participant, in [1, `limits.MAX_RUNS`] (a round's draws are held in memory).
    seed : int, default 0
        The study's seed: a run is a pure function of seed, participant and block.
    tear_probability : float, default `TEAR_PROBABILITY`
        Chance that each injurable ligament is torn in a run, in [0, 1].
    exclude_above_mpa : float, default `EXCLUDE_ABOVE_MPA`
        A run is excluded when its radioscaphoid mean pressure exceeds this at any frame of the sweep, MPa.
    max_attempts : int, optional
        Give up (`StudyError`) after this many runs of one participant; default 5 n + 100.
    load_direction : str, default `solver.settings.DEFAULT_LOADS`
        The sweeps' load direction (`LOAD_DIRECTIONS`): along the radius, or a tendon rig's.

    Raises
    ------
    StudyError
        No participant, a tear probability outside [0, 1], or an unknown load direction.
    InputError
        A participant named twice, or n or seed not an int in its range.
    """

    participants: tuple[str, ...]
    n: int
    seed: int = 0
    tear_probability: float = TEAR_PROBABILITY
    exclude_above_mpa: float = EXCLUDE_ABOVE_MPA
    max_attempts: int | None = None
    """Give up (StudyError) after this many runs of one participant; default 5 n + 100."""
    load_direction: str = DEFAULT_LOADS
    """The sweeps' load direction (`LOAD_DIRECTIONS`): along the radius, or a tendon rig's."""

    def __post_init__(self):
        object.__setattr__(self, "participants", tuple(self.participants))
        if not self.participants:
            raise StudyError("a study needs at least one participant")
        check_unique("participants", self.participants)
        check_int("n", self.n, 1, MAX_RUNS, "a round's draws are held in memory")
        check_int("seed", self.seed, 0, MAX_SEED)
        if not 0.0 <= self.tear_probability <= 1.0:
            raise StudyError(f"tear_probability must be in [0, 1], but got {self.tear_probability}")
        if self.load_direction not in LOAD_DIRECTIONS:
            raise StudyError(f"load_direction must be one of {LOAD_DIRECTIONS}, but got {self.load_direction!r}")

    @property
    def attempt_limit(self) -> int:
        return int(self.max_attempts) if self.max_attempts is not None else 5 * int(self.n) + 100

    def key(self) -> dict:
        """The fields that must match to resume a study in the same folder (the load direction only when
        not the axial default, so that a study logged before it existed resumes)."""
        return {
            "version": VERSION,
            "n": int(self.n),
            "seed": int(self.seed),
            "tear_probability": float(self.tear_probability),
            "exclude_above_mpa": float(self.exclude_above_mpa),
        } | ({} if self.load_direction == "axial" else {"load_direction": self.load_direction})
