"""`wrist-bench`: the command line of wrist-env (a thin shell over the package)."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from wrist_env.cli import figure_commands, identification_commands, participant_commands, study_commands
from wrist_env.errors import WristEnvError
from wrist_env.participants import registry


def parser() -> argparse.ArgumentParser:
    """The `wrist-bench` argument parser: every command, each with `--folder`."""
    p = argparse.ArgumentParser(prog="wrist-bench", description=__doc__)
    sub = p.add_subparsers(dest="command", required=True)
    folders = argparse.ArgumentParser(add_help=False)
    folders.add_argument(
        "--folder",
        action="append",
        help="register this participant folder first (repeatable; registered in every worker too)",
    )

    def command(name: str, *, folders_option: bool = True, **kwargs) -> argparse.ArgumentParser:
        return sub.add_parser(name, parents=[folders] if folders_option else [], **kwargs)

    participant_commands.add_commands(command)
    figure_commands.add_commands(command)
    study_commands.add_commands(command)
    identification_commands.add_commands(command)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Run one `wrist-bench` command; returns the exit status (2 for a project or file-system error: one line on
    stderr)."""
    args = parser().parse_args(argv)
    os.environ.setdefault("MPLBACKEND", "Agg")  # the commands save figures; none is shown

    try:
        if getattr(args, "folder", None):
            for folder in args.folder:
                registry.add_folder(folder)
        return args.run(args)
    except WristEnvError as exc:  # every project error (unknown calibrators too): one line, exit 2
        print(f"wrist-bench: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # `wrist-bench ... --json | head`: the reader left; say nothing more
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:  # a path the system refuses (--out a file, read-only, under /proc, too long): one line
        print(f"wrist-bench: error: {_os_error(exc)}", file=sys.stderr)
        return 2


def _os_error(exc: OSError) -> str:
    """One line naming the file and the system's reason."""
    where = f"{exc.filename}" + (f" -> {exc.filename2}" if exc.filename2 else "") + ": " if exc.filename else ""
    return f"{where}{exc.strerror or exc} ({type(exc).__name__})"
