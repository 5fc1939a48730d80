"""Bounds on the sizes and values a user can ask for, checked at the boundary before anything is allocated,
spawned or built.

Each size limit is far above any study the docs describe (Monte Carlo n 12,500; budgets of 300; batches of 64;
sweeps of 17 frames; Sobol n 64; 48 walkers x 1,200 steps) and below what this machine's memory or process
table survives: a Monte Carlo round holds its n draws (27 floats each) and the bookkeeping of every sample
id in memory, so n = 10^8 asked 20 GiB; `simulate --frames 3000000` asked 4 GB, `sensitivity --n 2000000`
2.5 GB, `posterior --walkers 5000000` 3.3 GB and rising (issue 53). Each value limit is the range in
which the value means something (angles within the wrist's reach, loads within a hand's). `check_int` and
`check_float` state the rule and the value; the command line's options take them as argparse types
(`bounded_int`, `bounded_float`), the library's functions call them too.
"""

from __future__ import annotations

import argparse
import math
import numbers
from collections.abc import Callable, Sequence

from wrist_env.errors import InputError

MAX_RUNS = 1_000_000
"""Monte Carlo successful runs per participant (`--n`)."""
MAX_BUDGET = 1_000_000
"""Evaluations of one calibration (`--budget`)."""
MAX_SEEDS = 10_000
"""Seeds per participant and calibrator (`--seeds`); also its runs over instances (instances x seeds)."""
MAX_INSTANCE = 10_000
"""The largest problem instance of a participant (`participants.instances`; each one made is a few
seconds of simulation and a few kB cached)."""
MAX_BATCH = 4_096
"""Monte Carlo runs per batch, one vector-env step (`--batch`)."""
MAX_WORKERS = 256
"""Local worker processes (`--workers`)."""
MAX_THREADS = 256
"""Numba threads per worker (`--threads`)."""
MAX_SEED = 2**32 - 1
"""Seeds are non-negative 32-bit integers, as every calibrator takes (`--seed`)."""
MAX_FRAMES = 10_000
"""Frames of one simulated sweep or hold (`simulate --frames`, `drivers.idealized`/`static`'s n_frames): the
idealized sweep has 17, the built-in trials 15; every frame's poses, contact and forces are held (about
1.3 kB a frame: 3 million frames took 4 GB before failing) and each is a quasi-static solve."""
MAX_SWEEP_DEG = 90.0
"""|flexion| and |extension| of the idealized sweep, deg (`simulate --flexion/--extension`): a wrist
reaches about 80 flexion and 70 extension (the studies sweep +-40); past a right angle the capitate is
turned where no wrist goes and the row dislocates."""
MAX_LOAD_N = 1_000.0
"""Compressive load on the capitate, N (`validate --load`): above the radiocarpal loads of a power grip
(a few hundred N; the sweeps take 10 N, the load-share check 100 N); a load is a push, so at least 0."""
MAX_FOSSA_SWEEP_DEG = 90.0
"""Half-range, deg, of each axis of the row's sweep that shapes the radius fossae (`--fossa-sweep`,
`BuildParams.fossa_sweep_deg`; default 20 and 10): the row turns ~0.7x the capitate's +-40, so a right
angle is past any wrist's reach; a half-range is at least 0 (0 0 moulds the fossae to the neutral row)."""
SWEEP_WHY = "deg; 0 0 moulds the fossae to the neutral row"
"""What a fossa sweep's refusal adds after its bounds."""
MAX_ULNAR_VARIANCE_MM = 5.0
"""|Ulnar variance|, mm, a build may seat the ulna at (`BuildParams.ulnar_variance_mm`, participant.toml's
`ulnar_variance_mm`; + ulna plus, by `anatomy.ulnar_variance`'s corner rule): adults measure about −4 to
+5 mm (mean +0.26 mm, Yoshioka 2007); beyond that the ulnar head leaves the sigmoid notch or enters the
lunate."""
MIN_SENSITIVITY_N = 2
"""Least Morris trajectories or Sobol base size (`sensitivity --n`): Morris's sigma is the spread of a
material's effects over the trajectories (one gives NaN); the smallest Sobol base is 2 (a power of 2)."""
MAX_SENSITIVITY_N = 4_096
"""Morris trajectories or the Sobol base size of a sensitivity study (`sensitivity --n`; documented 10 and
64): n x 23 or x 24 runs per motion (~100,000 at the limit, hours), the sample n x 24 x 22 floats (16 MB;
n = 2 million asked 2.5 GB while sampling)."""
MAX_WALKERS = MAX_BATCH
"""emcee's walkers (`posterior --walkers`; default 48): each step is one batched solver call of every
walker, the batch `MAX_BATCH` bounds."""
MAX_PARTICLES = MAX_BATCH
"""SMC's particles (`posterior --particles`; default 256): each move is one batched solver call of every
particle, the batch `MAX_BATCH` bounds."""
MAX_STEPS = 100_000
"""emcee's steps (`posterior --steps`; default 1,200, ~12 min): 100,000 are ~17 hours of walkers x steps
simulations; with the walkers also bounded by `MAX_CHAIN_DRAWS`."""
MAX_CHAIN_DRAWS = 4_000_000
"""Walkers x steps of one emcee run (default 48 x 1,200 = 57,600): the chain holds every draw (22 floats
and a log probability, 0.7 GB at the limit, copied once when the burn-in is cut), each a simulation."""
MAX_MCMC_STEPS = 1_000
"""SMC random-walk steps per particle and stage (`posterior --mcmc-steps`; default 5): each is a batched
solver call of every particle, so 1,000 a stage is already days for the default 256 particles."""
MAX_MAP_STARTS = 1_000
"""Gauss-Newton starts of the MAP search (`posterior --map-starts`; default 24): each start is up to 40
evaluations of a 22-column Jacobian, so 1,000 starts are ~a million simulations."""
MAX_SUBSET_RUNS = 100_000_000
"""Runs a Monte Carlo report fits on (`montecarlo-report --max-runs`): far above any log (3 participants x
`MAX_RUNS`); a subset as large as the log keeps every run, as leaving the option out does."""


def check_int(name: str, value: object, low: int, high: int, why: str = "") -> int:
    """`value` as an int if it is an integer in [low, high]; `InputError` stating the rule and the value."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not low <= value <= high:
        raise InputError(
            f"{name} must be an integer in [{low:,}, {high:,}]{f' ({why})' if why else ''}, but got {value!r}"
        )
    return int(value)


def check_float(name: str, value: object, low: float, high: float, why: str = "") -> float:
    """`value` as a float if it is a finite real number in [low, high] (NaN and infinities refused);
    `InputError` stating the rule and the value."""
    real = isinstance(value, numbers.Real) and not isinstance(value, bool)
    if not real or not math.isfinite(value) or not low <= value <= high:
        raise InputError(
            f"{name} must be a finite number in [{low:,g}, {high:,g}]{f' ({why})' if why else ''}, but got {value!r}"
        )
    return float(value)


def check_fossa_sweep(sweep_deg: Sequence[float]) -> tuple[float, float]:
    """(flexion, deviation) half-ranges, deg, as floats, if there are two, each finite and in
    [0, `MAX_FOSSA_SWEEP_DEG`]; `InputError` naming the value (before a template is swept or a model is
    built and cached from it)."""
    try:
        pair = tuple(sweep_deg)
    except TypeError:
        pair = ()
    if len(pair) != 2:
        raise InputError(f"fossa_sweep_deg must be two angles (flexion, deviation), deg, but got {sweep_deg!r}")
    return tuple(
        check_float(f"fossa_sweep_deg {axis}", a, 0.0, MAX_FOSSA_SWEEP_DEG, SWEEP_WHY)
        for axis, a in zip(("flexion", "deviation"), pair)
    )


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


def bounded_int(name: str, low: int, high: int, why: str = "") -> Callable[[str], int]:
    """An argparse `type`: the option's text as an int in [low, high] (`check_int`'s rule and message,
    so the command line and the library refuse alike), checked as the arguments parse, before
    anything is loaded or allocated."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = text  # not an integer: refused below, the text quoted
        return _as_usage_error(check_int, name, value, low, high, why)

    parse.__name__ = "integer"
    return parse


def bounded_float(name: str, low: float, high: float, why: str = "") -> Callable[[str], float]:
    """An argparse `type`: the option's text as a finite float in [low, high] (`check_float`: NaN and infinities
    refused), checked as the arguments parse."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = text
        return _as_usage_error(check_float, name, value, low, high, why)

    parse.__name__ = "number"
    return parse


def _as_usage_error(check, *args):
    """`check(*args)`, its `InputError` as argparse's `ArgumentTypeError` (argparse names the option)."""
    try:
        return check(*args)
    except InputError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
