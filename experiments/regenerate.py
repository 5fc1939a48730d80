"""Regenerate every committed result from real runs: the figures in `experiments/figures/`, `leaderboards/`
and `leaderboards/montecarlo/` (the maintainer's one command after a model change).

Runs, from the repository root, each step as the docs document it and prints its wall time:
the built-in models shipped with the package (`experiments/authoring/ship_models.py`), the figures (`wrist-bench figure ...`, `wrist-bench validate P1` … `P3`, whose JSON records the docs' validation page renders, the scaling benchmark `experiments/benchmarks/bench_scaling.py`), the full default benchmark
and its leaderboard (3 participants × instances 0–4 × 11 calibrators × 300 evaluations, seed = instance; Nevergrad's four
need the `[nevergrad]` extra) with its IOHanalyzer files (`[ioh]`), and the full
Monte Carlo study (P1 + P2, 2 × 12,500) with its report and the probe of where each injury moves the load, what a trial identifies (Morris and Sobol
sensitivity and the Fisher matrix at the hidden truth, P1–P3), the best calibrators with and without
the prior (`leaderboards/prior/`) and the Bayesian calibrator's coverage on the trials and on the
model's own trials (`leaderboards/posterior/`: emcee at 300 steps with the default 24 MAP starts
and prior refresh, and on the model's trials at the default 1,200 steps too, ~6-7 h (34-51 min a run measured), in
`leaderboards/posterior/steps1200/`; SMC on the model's trials; the posterior studies' saved runs are
committed (`leaderboards/posterior/runs/`, `steps1200/runs/`) so that they resume across sessions; where the built-in trials' model error comes from,
`experiments/research/model_error.py`, and the truth's standing under other likelihoods,
`experiments/research/capitate_likelihood.py`). The studies' run logs go to a fresh
folder `runs/regenerate-<commit>/` (a killed run resumes there when rerun at the same commit: the steps
already done, listed in its `steps_done.txt`, are skipped, and the interrupted study resumes from its
run log; `--runs DIR` resumes a folder made at another commit that simulates the same model).

Run: `python experiments/regenerate.py` (~6 h on a 2-core machine); `--figures-only` skips the
studies (~6 min).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FIGURES = "experiments/figures"  # the committed figures the docs show (the commands' own default is runs/figures)
# the posterior studies' saved runs are committed (0.4-0.5 MB a 1,200-step run, compressed): at 20-51 min a run
# (24 MAP starts, then 20,000-63,000 simulations), their 36 runs span sessions; a saved run is loaded, not rerun,
# and one sampled on another model is refused (`Posterior.model_hash`): delete them after a model change
POSTERIOR_RUNS = "leaderboards/posterior/runs"
STEPS1200_RUNS = "leaderboards/posterior/steps1200/runs"


def _commit() -> str:
    out = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    return out.stdout.strip() or "worktree"


def steps(runs: Path, figures_only: bool) -> list[list[str]]:
    """The commands, in order: `wrist-bench` argv lists, and the model-shipping script first."""
    figures = [
        ["python", "experiments/authoring/ship_models.py"],
        ["figure", "annotations", "--out", f"{FIGURES}/template_annotations.png"],
        ["figure", "model", "P1", "--out", f"{FIGURES}/model_P1.png"],
        ["figure", "pressure", "P1", "--out", f"{FIGURES}/pressure_P1.png"],
        ["figure", "kinematics", "P1", "--out", f"{FIGURES}/kinematics_P1.png"],
        ["figure", "animation", "P1", "--out", f"{FIGURES}/animation_P1.gif"],
        *(["validate", p, "--out", FIGURES] for p in ("P1", "P2", "P3")),
        ["python", "experiments/benchmarks/bench_scaling.py", "P1", "--out", f"{FIGURES}/scaling_P1.png"],
    ]
    if figures_only:
        return figures
    return figures + [
        ["benchmark", "--storage", "memory", "--out", str(runs / "benchmark"), "--leaderboard", "leaderboards"],
        ["iohanalyzer", "--runs", str(runs / "benchmark"), "--out", "leaderboards/iohanalyzer"],
        ["montecarlo", "P1", "P2", "--n", "12500", "--seed", "0", "--out", str(runs / "montecarlo")],
        ["montecarlo-report", "--runs", str(runs / "montecarlo"), "--out", "leaderboards/montecarlo"],
        [
            *("python", "experiments/research/injury_load_paths.py", "P1", "P2"),
            *("--out", "leaderboards/montecarlo/injury_load_paths.md"),
        ],
        ["sensitivity", "P1", "P2", "P3", "--n", "10", "--out", "leaderboards/sensitivity"],
        [
            "sensitivity",
            *("P1", "P2", "P3", "--method", "sobol", "--n", "128", "--motions", "calibrate"),
            *("--out", "leaderboards/sensitivity"),
        ],
        ["identifiability", "P1", "P2", "P3", "--out", "leaderboards/identifiability"],
        [
            "benchmark",
            *("--optimizers", "nelder-mead", "cmaes", "ng-ngopt", "surrogate", "--prior", "--seeds", "3"),
            *("--storage", "memory", "--out", str(runs / "prior"), "--leaderboard", "leaderboards/prior"),
        ],
        [
            "posterior",
            *("P1", "P2", "P3", "--seeds", "3", "--steps", "300"),
            *("--out", POSTERIOR_RUNS, "--report", "leaderboards/posterior"),
        ],
        [
            "posterior",
            *("P1", "P2", "P3", "--seeds", "3", "--steps", "300", "--model-trials"),
            *("--out", POSTERIOR_RUNS, "--report", "leaderboards/posterior"),
        ],
        [
            "posterior",
            *("P1", "P2", "P3", "--seeds", "3", "--model-trials"),
            *("--out", STEPS1200_RUNS, "--report", "leaderboards/posterior/steps1200"),
        ],
        [
            "posterior",
            *("P1", "P2", "P3", "--seeds", "3", "--sampler", "smc", "--model-trials"),
            *("--out", POSTERIOR_RUNS, "--report", "leaderboards/posterior"),
        ],
        ["python", "experiments/research/model_error.py"],
        ["python", "experiments/research/capitate_likelihood.py"],
    ]


def _require_extras() -> None:
    """The committed leaderboard includes Nevergrad's calibrators and IOHanalyzer files: refuse without them."""
    import importlib.util

    missing = [name for name in ("nevergrad", "ioh") if importlib.util.find_spec(name) is None]
    if missing:
        sys.exit(
            f"regenerate needs {', '.join(missing)} (the leaderboard's calibrators and files): "
            'pip install -e ".[nevergrad,ioh]"'
        )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figures-only", action="store_true", help="skip the benchmark and the Monte Carlo study")
    parser.add_argument("--runs", type=Path, help="the run folder to resume (default runs/regenerate-<commit>)")
    args = parser.parse_args(argv)
    if not args.figures_only:
        _require_extras()
    # relative to the repository root, where every step runs: the logs and reports name it so
    runs = args.runs.resolve().relative_to(ROOT) if args.runs else Path("runs") / f"regenerate-{_commit()}"
    (ROOT / runs).mkdir(parents=True, exist_ok=True)
    log = ROOT / runs / "steps_done.txt"
    done_before = set(log.read_text().splitlines()) if log.exists() else set()
    for step in steps(runs, args.figures_only):
        script = step[0] == "python"
        shown = " ".join(step) if script else "wrist-bench " + " ".join(step)
        if shown in done_before:
            print(f"$ {shown}  (done before, skipped)", flush=True)
            continue
        print(f"$ {shown}", flush=True)
        start = time.perf_counter()
        command = [sys.executable, *step[1:]] if script else [sys.executable, "-m", "wrist_env.cli", *step]
        done = subprocess.run(command, cwd=ROOT)
        # validate exits 1 when a published check fails: its figure and table are still the result
        if done.returncode not in (0, 1) or (done.returncode == 1 and step[0] != "validate"):
            sys.exit(f"`{shown}` failed (exit status {done.returncode})")
        print(f"  {time.perf_counter() - start:.0f} s", flush=True)
        with log.open("a") as f:
            f.write(shown + "\n")


if __name__ == "__main__":
    main()
