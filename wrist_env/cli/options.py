"""The options several `wrist-bench` commands share, each declared here once."""

from __future__ import annotations

import argparse


def out_option(s: argparse.ArgumentParser, default: str | None = None, what: str = "output folder") -> None:
    """`--out`: where the command writes (`what`), its default shown in the help."""
    s.add_argument("--out", default=default, help=f"{what} (default {default})" if default else what)


def scheduler_option(s: argparse.ArgumentParser, unit: str) -> None:
    """`--scheduler`: a dask.distributed scheduler address; one task per `unit`."""
    s.add_argument(
        "--scheduler", help=f"dask.distributed scheduler address (e.g. tcp://host:8786); one task per {unit}"
    )
