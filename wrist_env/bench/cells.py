"""The benchmark's cells: participants × instances × calibrators × seeds (`make_cells`), each a `RunKey`, and
the convention that a run on instance k is seeded with k unless seeds are given (COCO's)."""

from __future__ import annotations

import itertools
import numbers
from collections.abc import Iterable, Sequence

from wrist_env.bench.schema import RunKey
from wrist_env.errors import InputError
from wrist_env.limits import MAX_INSTANCE, MAX_SEEDS, check_int, check_unique

__all__ = ["SEED_IS_INSTANCE", "make_cells"]


SEED_IS_INSTANCE = "instance"
"""`seeds` of `make_cells` and `benchmark`: one run per instance, seeded with the instance's number (COCO's
convention: a run on instance k uses seed k)."""


def make_cells(
    participants: Sequence[str],
    optimizers: Sequence[str],
    seeds: int | Iterable[int] | str,
    budget: int,
    instances: int | Iterable[int] | None = None,
) -> list[RunKey]:
    """The benchmark's cells: participants × instances × optimizers × seeds, in that order.

    Parameters
    ----------
    participants : sequence of str
        Participant names, each once.
    optimizers : sequence of str
        Calibrator names (`optimizers.available()`, optionally with ``+prior``), each once.
    seeds : int, sequence of int or "instance"
        A count n: seeds 0 … n−1 on every instance; a list of seeds; or `SEED_IS_INSTANCE` ("instance"):
        one run per instance, seeded with the instance's number.
    budget : int
        Evaluations per cell.
    instances : int, sequence of int or None, default None
        A count n: the drawn instances 1 … n; a list of instances (0: the shipped problem); None: instance
        0 alone, the benchmark before instances.

    Returns
    -------
    list of RunKey
        One key (participant, optimizer, seed, budget, instance) per cell; its ``name`` names the cell's
        files in the run log.

    Raises
    ------
    InputError
        A list is empty or repeats a name, instance or seed, or a size is out of bounds (`limits`).

    Examples
    --------
    >>> from wrist_env.bench import make_cells
    >>> cells = make_cells(["P1", "P2"], ["cmaes", "random"], seeds=2, budget=40)
    >>> len(cells)  # 2 participants × 1 instance × 2 calibrators × 2 seeds
    8
    >>> [c.seed for c in make_cells(["P1"], ["cmaes"], "instance", 300, instances=3)]
    [1, 2, 3]
    """
    instances, seeds = _instances(instances), _seeds(seeds)
    if not seeds or not participants or not optimizers:
        raise InputError("a benchmark needs at least one participant, optimizer and seed")
    if len(instances) * len(seeds) > MAX_SEEDS:  # checked before the cells are made (10^8 asked ~20 GB)
        raise InputError(
            f"runs per participant and calibrator (instances x seeds) must be at most {MAX_SEEDS:,}, but got "
            f"{len(instances):,} x {len(seeds):,}"
        )
    participants, optimizers = check_unique("participants", participants), check_unique("optimizers", optimizers)
    return [
        RunKey(p, o, k if s is None else s, budget, k)
        for p, k, o, s in itertools.product(participants, instances, optimizers, seeds)
    ]


def _seeds(seeds: int | Iterable[int] | str) -> list[int | None]:
    """`make_cells`'s seeds as a list: a count n → 0 … n−1; a list checked; `SEED_IS_INSTANCE` → [None] (the
    seed is the cell's instance)."""
    if isinstance(seeds, str):
        if seeds != SEED_IS_INSTANCE:
            raise InputError(f"seeds must be a count, a list of seeds or {SEED_IS_INSTANCE!r}, but got {seeds!r}")
        return [None]
    if isinstance(seeds, numbers.Integral):
        return list(range(check_int("seeds", seeds, 1, MAX_SEEDS)))
    return check_unique("seeds", seeds)


def _instances(instances: int | Iterable[int] | None) -> list[int]:
    """`make_cells`'s instances as a list: None → [0]; a count n → 1 … n; a list checked (`limits`)."""
    if instances is None:
        return [0]
    if isinstance(instances, numbers.Integral):
        return list(range(1, check_int("instances", instances, 1, MAX_INSTANCE) + 1))
    instances = check_unique("instances", [check_int("instance", k, 0, MAX_INSTANCE) for k in instances])
    if not instances:
        raise InputError("a benchmark needs at least one instance (or none given: instance 0)")
    return instances
