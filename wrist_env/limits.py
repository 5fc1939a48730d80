"""Bounds on the sizes a user can ask for, checked at the boundary before anything is allocated or spawned.

Each limit is far above any study in the README (Monte Carlo n 12,500; budgets of 300; batches of 64)
and below what this machine's memory or process table survives: a Monte Carlo round holds its n
draws (27 floats each) and the bookkeeping of every sample id in memory, so n = 10^8 asked 20 GiB.
"""

from __future__ import annotations

import numbers

from wrist_env.errors import InputError

MAX_RUNS = 1_000_000
"""Monte Carlo successful runs per participant (`--n`)."""
MAX_BUDGET = 1_000_000
"""Evaluations of one calibration (`--budget`)."""
MAX_SEEDS = 10_000
"""Seeds per participant and calibrator (`--seeds`)."""
MAX_BATCH = 4_096
"""Monte Carlo runs per batch, one vector-env step (`--batch`)."""
MAX_WORKERS = 256
"""Local worker processes (`--workers`)."""
MAX_THREADS = 256
"""Numba threads per worker (`--threads`)."""
MAX_SEED = 2**32 - 1
"""Seeds are non-negative 32-bit integers, as every calibrator takes (`--seed`)."""


def check_int(name: str, value: object, low: int, high: int, why: str = "") -> int:
    """`value` as an int if it is an integer in [low, high]; `InputError` stating the rule and the value."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not low <= value <= high:
        raise InputError(
            f"{name} must be an integer in [{low:,}, {high:,}]{f' ({why})' if why else ''}, but got {value!r}"
        )
    return int(value)


def check_unique(name: str, values) -> list:
    """`values` as a list if none repeats; `InputError` naming the repeats."""
    values = list(values)
    repeats = sorted({str(v) for v in values if values.count(v) > 1})
    if repeats:
        raise InputError(f"{name} must not repeat, but got {values} ({', '.join(repeats)} more than once)")
    return values


MAX_TRIAL_FRAMES = 1_000
"""Frames of one trial (a trial CSV's frames, participant.toml's `frames`). A 4DCT motion has tens of
frames (the built-in trials 15); every frame is simulated for every design and its outputs kept (~2.2 kB
per frame and design: poses, contact, bundle forces, the RSC membrane's 45 nodes), so a batch of 64
designs of 1,000 frames holds ~140 MB and takes ~70 times a built-in trial's time; a trial sampled
faster is to be subsampled. Checked on the CSV's row count before it is parsed."""
