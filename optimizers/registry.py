"""Calibrators by name: a decorator for ours, the entry-point group `wrist_env.optimizers` for others'.

A third-party package adds one without touching wrist-env::

    [project.entry-points."wrist_env.optimizers"]
    my-method = "my_package.module:MyOptimizer"
"""

from __future__ import annotations

from collections.abc import Callable
from importlib.metadata import entry_points
from typing import TYPE_CHECKING, Any

from wrist_env.errors import WristEnvError

if TYPE_CHECKING:
    from optimizers.base import Optimizer

__all__ = [
    "ENTRY_POINT_GROUP",
    "UnknownOptimizerError",
    "register",
    "unavailable",
    "available",
    "get",
    "make",
]

ENTRY_POINT_GROUP = "wrist_env.optimizers"
_REGISTRY: dict[str, type] = {}
_UNAVAILABLE: dict[str, str] = {}  # name -> why it is not registered here (what to install)


class UnknownOptimizerError(WristEnvError, KeyError):
    """An optimizer name that is not registered (the message lists the valid ones).

    Raised by `get` and `make` (so by the benchmark and ``wrist-bench calibrate``); for a calibrator whose
    optional library is missing, the message says what to install. A `KeyError` too, printed without
    KeyError's quotes.
    """

    def __str__(self) -> str:
        return str(self.args[0])


def register(name: str) -> Callable[[type], type]:
    """Class decorator: make an `Optimizer` subclass available under `name`.

    The benchmark, ``wrist-bench calibrate --optimizer NAME`` and the contract tests then find it by name;
    `name` is set as the class's ``name``.

    Parameters
    ----------
    name : str
        The calibrator's name, unique in the registry.

    Returns
    -------
    callable
        The decorator, which registers the class and returns it unchanged.

    Raises
    ------
    ValueError
        `name` is taken by another class.

    Examples
    --------
    >>> from optimizers import Optimizer, register
    >>> @register("my-random")
    ... class MyRandom(Optimizer):
    ...     def _ask(self, n_max):
    ...         return self.rng.uniform(self.lower, self.upper, (min(n_max, 8), self.dim))
    >>> import optimizers
    >>> "my-random" in optimizers.available()
    True
    """

    def decorate(cls):
        if name in _REGISTRY and _REGISTRY[name] is not cls:
            raise ValueError(f"optimizer name {name!r} is already taken by {_REGISTRY[name].__qualname__}")
        cls.name = name
        _REGISTRY[name] = cls
        return cls

    return decorate


def unavailable(name: str, reason: str) -> None:
    """Record a calibrator that exists but cannot run here, and why.

    Parameters
    ----------
    name : str
        The calibrator's registry name.
    reason : str
        Why it cannot run here (e.g. an optional extra to install).
    """
    _UNAVAILABLE[name] = reason


def _load_plugins() -> None:
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        if ep.name not in _REGISTRY:
            cls = ep.load()
            register(ep.name)(cls)


def available() -> tuple[str, ...]:
    """Names of all registered calibrators: built-in and from the entry-point group, sorted.

    Returns
    -------
    tuple of str
        The names, sorted.
    """
    _load_plugins()
    return tuple(sorted(_REGISTRY))


def get(name: str) -> type:
    """The calibrator class registered as `name`.

    Parameters
    ----------
    name : str
        A registered calibrator's name (`available()`).

    Returns
    -------
    type
        The `Optimizer` subclass.

    Raises
    ------
    UnknownOptimizerError
        `name` is not registered (the message lists the registered ones), or its optional library is not
        installed here.
    """
    if name not in _REGISTRY:
        _load_plugins()
    if name in _UNAVAILABLE and name not in _REGISTRY:
        raise UnknownOptimizerError(f"optimizer {name!r} is not available here: {_UNAVAILABLE[name]}")
    if name not in _REGISTRY:
        raise UnknownOptimizerError(f"unknown optimizer {name!r}; available: {', '.join(available())}")
    return _REGISTRY[name]


def make(name: str, dim: int, budget: int, seed: int = 0, **options: Any) -> Optimizer:
    """An instance of the calibrator `name`.

    Parameters
    ----------
    name : str
        A registered calibrator's name (`available()`).
    dim : int
        The number of variables (22 normalized materials in the benchmark).
    budget : int
        Evaluations allowed.
    seed : int, default 0
        The calibrator's seed.
    **options
        The calibrator's options, names from its ``OPTIONS``.

    Returns
    -------
    Optimizer
        A fresh calibrator over the box [-1, 1]^dim.

    Raises
    ------
    UnknownOptimizerError
        `name` is not registered (the message lists the registered ones).
    OptionError
        An option the calibrator does not declare.
    ValueError
        dim or budget below 1.

    Examples
    --------
    >>> from optimizers import make
    >>> opt = make("random", dim=3, budget=8, seed=0)
    >>> opt.ask().shape[1]
    3
    """
    return get(name)(dim=dim, budget=budget, seed=seed, **options)
