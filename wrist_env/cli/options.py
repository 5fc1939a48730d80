"""The options several `wrist-bench` commands share, each declared here once."""

from __future__ import annotations

import argparse

from wrist_env.limits import MAX_INSTANCE, MAX_SEED, bounded_int
from wrist_env.solver.settings import DEFAULT_LOADS, LOAD_DIRECTIONS


def out_option(s: argparse.ArgumentParser, default: str | None = None, what: str = "output folder") -> None:
    """`--out`: where the command writes (`what`), its default shown in the help."""
    s.add_argument("--out", default=default, help=f"{what} (default {default})" if default else what)


def scheduler_option(s: argparse.ArgumentParser, unit: str) -> None:
    """`--scheduler`: a dask.distributed scheduler address; one task per `unit`."""
    s.add_argument(
        "--scheduler", help=f"dask.distributed scheduler address (e.g. tcp://host:8786); one task per {unit}"
    )


PARTICIPANT_HELP = "participant: built-in P1, P2, P3 or a registered folder's name (see `wrist-bench participants`)"
PARTICIPANTS_HELP = "participant names (`wrist-bench participants` lists them)"


def participant_argument(s: argparse.ArgumentParser, help: str = PARTICIPANT_HELP, **kwargs) -> None:
    """The positional `participant`."""
    s.add_argument("participant", help=help, **kwargs)


def participants_argument(s: argparse.ArgumentParser, help: str = PARTICIPANTS_HELP) -> None:
    """The positional `participants` (one or more)."""
    s.add_argument("participants", nargs="+", help=help)


def load_direction_option(s: argparse.ArgumentParser, help: str) -> None:
    """`--load-direction`: the direction of the loads (`LOAD_DIRECTIONS`, default along the radius)."""
    s.add_argument("--load-direction", choices=LOAD_DIRECTIONS, default=DEFAULT_LOADS, help=help)


def json_option(s: argparse.ArgumentParser, what: str) -> None:
    """`--json`: print `what` as JSON instead of a table."""
    s.add_argument("--json", action="store_true", help=f"print {what} as JSON")


def seed_option(s: argparse.ArgumentParser, what: str, default: int | None = 0, default_help: str = "0") -> None:
    """`--seed` (default `default`, described as `default_help`)."""
    s.add_argument(
        "--seed", type=bounded_int("seed", 0, MAX_SEED), default=default, help=f"{what} seed (default {default_help})"
    )


INSTANCE = bounded_int("instance", 0, MAX_INSTANCE)
"""An instance's number on the command line (`participants.instances`; 0 the shipped problem)."""
INSTANCES = bounded_int("instances", 1, MAX_INSTANCE)
"""A count of instances on the command line (1 … n)."""


def parse_instances(text: str) -> int | list[int]:
    """`--instances`: "n", a count (the drawn instances 1 … n); "a-b", instances a … b; "a,b,…", a list
    (0 the shipped problem). Every number checked as `limits.bounded_int` checks it (argparse names the
    option and the value)."""
    text = text.strip()
    if "," in text:
        return [INSTANCE(piece) for piece in text.split(",") if piece.strip()]
    if "-" in text.lstrip("-"):
        first, _, last = text.partition("-")
        first, last = INSTANCE(first), INSTANCE(last)
        if last < first:
            raise argparse.ArgumentTypeError(f"instances a-b must have a <= b, but got {text!r}")
        return list(range(first, last + 1))
    return INSTANCES(text)


parse_instances.__name__ = "instances"


def instances_option(s: argparse.ArgumentParser) -> None:
    """`--instances`: problem instances of each participant (`parse_instances`); the default is the command's."""
    s.add_argument(
        "--instances",
        type=parse_instances,
        help="problem instances of each built-in participant, each a hidden truth drawn from the prior with its "
        "own trials: N (instances 1 .. N), A-B (A .. B) or a list A,B,... (0: the shipped problem). A run on "
        "instance k uses seed k unless --seeds is given (COCO's convention). Default: instances 0-4 of built-in "
        "participants (instance 0 alone with --seeds or another participant)",
    )


def progress_option(s: argparse.ArgumentParser) -> None:
    """`--no-progress`: no tqdm bar."""
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
