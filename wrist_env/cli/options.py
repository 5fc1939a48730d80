"""The options several `wrist-bench` commands share, each declared here once."""

from __future__ import annotations

import argparse

from wrist_env.limits import MAX_SEED, bounded_int
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


def seed_option(s: argparse.ArgumentParser, what: str) -> None:
    """`--seed` (default 0)."""
    s.add_argument("--seed", type=bounded_int("seed", 0, MAX_SEED), default=0, help=f"{what} seed (default 0)")


def progress_option(s: argparse.ArgumentParser) -> None:
    """`--no-progress`: no tqdm bar."""
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
