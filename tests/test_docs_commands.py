"""Every `wrist-bench` command the README and the docs show parses, and what it writes, run from the repository root,
is ignored by git (so following the README leaves `git status` clean; only `experiments/regenerate.py`,
the maintainer's command, rewrites committed results)."""

import shlex
import subprocess
from pathlib import Path

import pytest

import wrist_env
from wrist_env.cli import parser

ROOT = Path(wrist_env.__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]  # the hand-written pages (results/ is rendered)
OUTPUTS = ("out", "out_folder", "leaderboard", "report")  # the options through which a command writes files


def readme_commands() -> list[list[str]]:
    """The `wrist-bench` lines of the pages' bash blocks (after `&&` too), comments stripped, as argv lists."""
    commands, in_bash = [], False
    for line in (line for page in PAGES for line in page.read_text().splitlines()):
        if line.startswith("```"):
            in_bash = line.strip() == "```bash"
            continue
        if in_bash:
            for part in line.split("&&"):
                words = shlex.split(part, comments=True)
                if words[:1] == ["wrist-bench"]:
                    commands.append(words[1:])
    return commands


def written_paths(argv: list[str]) -> list[Path]:
    """Where a command writes, relative to the repository root (the documented default when not given)."""
    args = parser().parse_args(argv)
    paths = [getattr(args, name) for name in OUTPUTS if getattr(args, name, None)]
    if args.command in ("figure", "validate") and not args.out:
        paths.append("runs/figures")  # wrist_env.figures.draw.FIGURES without $WRIST_ENV_FIGURES
    return [Path(p) for p in paths]


def ignored_by_git(path: Path) -> bool:
    done = subprocess.run(["git", "check-ignore", "-q", str(path)], cwd=ROOT)
    if done.returncode == 128:  # not a git checkout (an installed copy): the repository's own rule
        return path.parts[0] == "runs"
    return done.returncode == 0


def test_the_docs_show_the_commands():
    commands = readme_commands()
    assert len(commands) >= 20
    assert {c[0] for c in commands} >= {"benchmark", "export", "build", "evaluate", "figure", "validate", "montecarlo"}


@pytest.mark.parametrize("argv", readme_commands(), ids=" ".join)
def test_a_readme_command_parses_and_writes_only_where_git_ignores(argv):
    for path in written_paths(argv):
        assert not path.is_absolute() and ".." not in path.parts, path
        assert ignored_by_git(path), f"`wrist-bench {' '.join(argv)}` writes {path}, which git tracks or would show"


def test_an_output_git_tracks_is_caught():
    assert not ignored_by_git(Path("leaderboards"))
    assert written_paths(["leaderboard", "--out", "leaderboards"]) == [Path("leaderboards")]
