"""Benchmark: how long a newcomer waits for the first simulation, compilation included.

For this checkout and, with `--against PATH`, another one (an older commit's worktree), in turn
(A B A B …, so a drift of the shared machine's speed hits both), each in a fresh Python process:
- cold: the first simulation of P1's calibration trial with an empty Numba cache (`NUMBA_CACHE_DIR`
  a new folder): imports, the model loaded (built-in, shipped), the kernel compiled, the run;
- warm: the same in a new process over the cache the cold run left (the compiled kernel loaded);
- `wrist-bench --help`: the command line's answer, whole process.
Prints each figure's median over the repeats and, with `--against`, the ratio this / that.

Run: `python experiments/benchmarks/bench_cold_start.py [--against PATH] [--repeats 3] [--out FILE]`
(`--out`: also write the table, with both commits and the machine, as Markdown; the solver page of the
docs includes `docs/speed/cold_start.md`).
A cold run takes a minute or more: on a shared machine expect ±15 %.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parents[2]
FIRST_SIMULATION = """
import json, time
start = time.perf_counter()
from wrist_env import design
from wrist_env.participants import registry
from wrist_env.solver.drivers import trial_driver
from wrist_env.solver.simulate import simulate
imported = time.perf_counter()
model = registry.load_model("P1")
driver = trial_driver(model, registry.trial("P1", "calibrate"))
loaded = time.perf_counter()
result = simulate(model, design.population(), driver)
done = time.perf_counter()
assert result.ok, result.message
print(json.dumps({"import_s": imported - start, "model_s": loaded - imported, "first_simulation_s": done - loaded}))
"""


def _run(tree: Path, cache: Path, program: list[str]) -> tuple[float, str]:
    env = dict(os.environ, PYTHONPATH=str(tree), NUMBA_CACHE_DIR=str(cache), MPLBACKEND="Agg")
    start = time.perf_counter()
    out = subprocess.run([sys.executable, *program], env=env, cwd=tempfile.gettempdir(), capture_output=True, text=True)
    wall = time.perf_counter() - start
    if out.returncode != 0:
        raise SystemExit(f"{tree}: {' '.join(program)} failed:\n{out.stderr[-2000:]}")
    return wall, out.stdout


def measure(tree: Path) -> dict[str, float]:
    """One cold run, one warm run and one `--help` of the checkout at `tree`."""
    figures = {}
    with tempfile.TemporaryDirectory(prefix="numba-cache-") as cache:
        for kind in ("cold", "warm"):
            wall, out = _run(tree, Path(cache), ["-c", FIRST_SIMULATION])
            parts = json.loads(out.strip().splitlines()[-1])
            figures[f"{kind}: whole process, s"] = wall
            figures[f"{kind}: first simulation (compile or load + run), s"] = parts["first_simulation_s"]
        figures["wrist-bench --help, s"] = _run(tree, Path(cache), ["-m", "wrist_env.cli", "--help"])[0]
    return figures


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--against", type=Path, help="another checkout to compare with (e.g. a worktree of main)")
    p.add_argument("--repeats", type=int, default=3, help="runs of each checkout, in turn (default 3)")
    p.add_argument("--out", type=Path, help="also write the table here (Markdown), with the commits and machine")
    args = p.parse_args()
    trees = {"this": HERE} | ({"against": args.against.resolve()} if args.against else {})
    runs: dict[str, list[dict[str, float]]] = {k: [] for k in trees}
    for r in range(args.repeats):
        for name, tree in trees.items():
            runs[name].append(measure(tree))
            print(f"repeat {r + 1}/{args.repeats}, {name} ({tree}): done", file=sys.stderr, flush=True)
    lines = [f"| figure (median of {args.repeats}) | this |" + (" against | this / against |" if args.against else "")]
    lines.append("|---|---|" + ("---|---|" if args.against else ""))
    lines += median_rows(runs)
    print("\n".join(lines))
    if args.out:
        write_table(args.out, "bench_cold_start.py", trees, lines)


def median_rows(runs: dict[str, list[dict[str, float]]], prefix: str = "", spec: str = ".2f") -> list[str]:
    """Markdown rows, one per figure of the runs: its median over the runs of "this" tree and, where measured,
    over those of "against", and their ratio."""
    keys = list(runs["this"][0])
    median = {name: {k: float(np.median([m[k] for m in ms])) for k in keys} for name, ms in runs.items()}
    rows = []
    for k in keys:
        row = f"| {prefix}{k} | {median['this'][k]:{spec}} |"
        if "against" in runs:
            row += f" {median['against'][k]:{spec}} | {median['this'][k] / median['against'][k]:.2f} |"
        rows.append(row)
    return rows


def write_table(out: Path, script: str, trees: dict[str, Path], lines: list[str]) -> None:
    """Write a comparison table (Markdown `lines`) to `out`, headed by the command that made it, the date,
    the machine and each checkout's commit."""
    made = " ".join(["python", f"experiments/benchmarks/{script}", *sys.argv[1:]])
    about = [f"{name}: {_commit(tree)}" for name, tree in trees.items()]
    head = (
        f"Measured by `{made}` on {time.strftime('%Y-%m-%d')}, {os.cpu_count()} cores, Python "
        f"{sys.version.split()[0]}; {'; '.join(about)}.\n\n"
    )
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(head + "\n".join(lines) + "\n")


def _commit(tree: Path) -> str:
    """The checkout's commit, and whether its files differ from it."""
    git = ["git", "-C", str(tree)]
    head = subprocess.run([*git, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(
        [*git, "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True
    ).stdout
    return f"{head or 'unknown'}{' with uncommitted changes' if dirty.strip() else ''}"


if __name__ == "__main__":
    main()
