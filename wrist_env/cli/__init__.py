"""`wrist-bench`: the command line of wrist-env (a thin shell over the package)."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from importlib import import_module
from pkgutil import resolve_name

from wrist_env.errors import UsageError, WristEnvError

__all__ = ["COMMANDS", "main", "parser"]

COMMANDS = {
    "participants": ("participant_commands", "list the known participants"),
    "build": ("participant_commands", "build (or load from cache) a participant model"),
    "export": (
        "participant_commands",
        "write a built-in participant as a participant folder (a template for your own)",
    ),
    "simulate": ("participant_commands", "simulate a participant and print the per-frame outputs"),
    "evaluate": ("participant_commands", "score one design on a participant's task (cost, per-DOF errors)"),
    "validate": (
        "figure_commands",
        "check the model against published wrist measurements (exit 1 if any check fails)",
    ),
    "figure": ("figure_commands", "write a figure (PNG)"),
    "calibrate": ("study_commands", "calibrate a participant's ligament materials with one calibrator"),
    "benchmark": (
        "study_commands",
        "run participants x instances x calibrators x seeds into a resumable run log, then the leaderboard",
    ),
    "leaderboard": ("study_commands", "write the leaderboards of a benchmark run log"),
    "iohanalyzer": ("study_commands", "write a benchmark run log in IOHanalyzer's format (through ioh's logger)"),
    "montecarlo": (
        "study_commands",
        "Monte Carlo injury study: n successful idealized sweeps per participant (preprint 2.3.2)",
    ),
    "montecarlo-report": ("study_commands", "Tables 5-6 and Figures 8-10 of a Monte Carlo run log"),
    "checksum": ("study_commands", "checksum a run log written before wrist-env kept checksums (only one you trust)"),
    "sensitivity": (
        "identification_commands",
        "global sensitivity of the cost and the 12 DOF errors to the 22 materials (SALib)",
    ),
    "identifiability": (
        "identification_commands",
        "what the calibration and held-out trials identify at the hidden truth (Fisher matrix)",
    ),
    "posterior": (
        "identification_commands",
        "Bayesian calibration: the posterior of the 22 materials given the calibration trial (emcee or SMC)",
    ),
}
"""Every `wrist-bench` command: the module of `wrist_env.cli` that declares its arguments, and its one-line
help. A command's module is loaded only when that command is named, so `wrist-bench --help` loads none of
them; what runs it (`wrist_env.cli.run`, the solver and the rest) only once its arguments have parsed."""


class _Parser(argparse.ArgumentParser):
    """argparse's parser, whose usage errors (an option's value out of its bounds, a missing or unknown
    argument) are `UsageError`s: one line naming the command, the option and the value, exit 2, as every
    other error of `main` (argparse would print the usage and exit)."""

    def error(self, message: str):
        command = self.prog.removeprefix("wrist-bench").strip()
        raise UsageError(f"{command}: {message}" if command else message)


def parser(selected: str | None = None) -> argparse.ArgumentParser:
    """The `wrist-bench` argument parser, every command with `--folder`.

    Parameters
    ----------
    selected : str, optional
        A command's name: only the commands of its module get their own arguments (from the module), the
        others are listed by name and help alone, their modules not imported; "" for none; None (the
        default) gives every command its arguments.

    Returns
    -------
    argparse.ArgumentParser
        The parser, one subcommand per entry of `COMMANDS`.
    """
    p = _Parser(prog="wrist-bench", description=__doc__)
    sub = p.add_subparsers(dest="command", required=True)
    folders = argparse.ArgumentParser(add_help=False)
    folders.add_argument(
        "--folder",
        action="append",
        help="register this participant folder first (repeatable; registered in every worker too)",
    )

    def command(name: str, *, folders_option: bool = True, **kwargs) -> argparse.ArgumentParser:
        kwargs.setdefault("help", COMMANDS[name][1])
        return sub.add_parser(name, parents=[folders] if folders_option else [], **kwargs)

    loaded = set()
    for name, (module, help) in COMMANDS.items():
        if selected is None or (selected and module == COMMANDS[selected][0]):
            if module not in loaded:
                import_module(f"wrist_env.cli.{module}").add_commands(command)
                loaded.add(module)
        else:
            sub.add_parser(name, help=help, add_help=False)
    return p


def _named(argv: Sequence[str]) -> str | None:
    """The command named on the command line, if it is one."""
    for token in argv:
        if not token.startswith("-"):
            return token if token in COMMANDS else None
    return None


def main(argv: Sequence[str] | None = None) -> int:
    """Run one `wrist-bench` command; returns the exit status.

    A project error (`WristEnvError`), a usage error or a file-system error is one line on stderr, not a
    traceback.

    Parameters
    ----------
    argv : sequence of str, optional
        The command line after ``wrist-bench`` (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        The exit status: the command's (0 on success; ``validate`` 1 if a check fails), 2 for a usage,
        project or file-system error, 130 for Ctrl-C.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    name = _named(argv)
    try:
        args = parser(name or "").parse_args(argv)  # every option's bounds checked here, before any work
        os.environ.setdefault("MPLBACKEND", "Agg")  # the commands save figures; none is shown
        run = resolve_name(f"{__name__}.run.{args.run}")  # "module:function" of wrist_env.cli.run, imported now
        if getattr(args, "folder", None):
            from wrist_env.participants import registry  # only when a folder is named: it loads the builder

            for folder in args.folder:
                registry.add_folder(folder)
        return run(args)
    except WristEnvError as exc:  # every project error (unknown calibrators too): one line, exit 2
        print(f"wrist-bench: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:  # Ctrl-C: a study's runner says what was saved (`errors.Interrupted`)
        print(f"wrist-bench: {exc or 'interrupted'}", file=sys.stderr)
        return 130
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
