"""Benchmark: how long a participant build takes, first run included.

Each participant is built with `wrist-bench build NAME --no-cache --json` in a
fresh Python process (imports and all), into a throw-away cache. Prints the
wall time, the pipeline's own step timings, and the ratio to the preprint's
2 hours per participant. Run: `python experiments/bench_build.py [P1 P2 P3]`.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

PREPRINT_SECONDS = 2 * 3600.0


def main(names: list[str]) -> None:
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, WRIST_ENV_CACHE=cache)
        rows = []
        print(
            f"{'participant':<12}{'wall s':>8}{'build s':>9}{'morph':>7}{'cartilage':>10}{'grids':>7}{'× faster than 2 h':>19}"
        )
        for name in names:
            start = time.perf_counter()
            out = subprocess.run(
                [sys.executable, "-m", "wrist_env.cli", "build", name, "--no-cache", "--json"],
                env=env,
                check=True,
                capture_output=True,
                text=True,
            ).stdout
            wall = time.perf_counter() - start
            summary = json.loads(out)
            t = summary["timings_s"]
            print(
                f"{name:<12}{wall:>8.1f}{summary['build_seconds']:>9.1f}{t['morph']:>7.1f}{t['cartilage']:>10.1f}"
                f"{t['grids']:>7.1f}{PREPRINT_SECONDS / wall:>19.0f}"
            )
            rows.append((name, wall, summary))
    print()
    print(
        "| participant | build, first run (s) | morph error mean / max (mm) | joint space RS / RL / SL / SC / LC (mm) "
        "| radius cartilage mean (mm) | contact law R² |"
    )
    print("|---|---|---|---|---|---|")
    for name, wall, s in rows:
        err = s["morph_error_mm"]
        mean = sum(e["mean"] for e in err.values()) / len(err)
        worst = max(e["max"] for e in err.values())
        space = " / ".join(f"{g:.2f}" for g in s["joint_space_mm"].values())
        radius = s["cartilage"]["articulations"]["radius-scaphoid"]["thickness_mm"]["radius"]["mean"]
        print(f"| {name} | {wall:.1f} | {mean:.3f} / {worst:.2f} | {space} | {radius:.2f} | {s['contact_law_r2']} |")


if __name__ == "__main__":
    main(sys.argv[1:] or ["P1", "P2", "P3"])
