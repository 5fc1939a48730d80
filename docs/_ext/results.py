"""Sphinx extension: the results pages, rendered at build time from the committed results files.

No number on a results page is typed by hand: each page reads the files that
`python experiments/regenerate.py` writes (`leaderboards/`, `experiments/figures/`)
and lays them out as tables and figures. A missing file is a build error.
"""

from __future__ import annotations

import json
import math
import re
import subprocess
from pathlib import Path

import pandas as pd

from wrist_env.bench.leaderboard.readme import md_table
from wrist_env.validation.report import band_text

ROOT = Path(__file__).resolve().parents[2]
BOARDS = ROOT / "leaderboards"
FIGURES = ROOT / "experiments" / "figures"
PARTICIPANTS = ("P1", "P2", "P3")


def table(header: list[str], rows: list[list]) -> str:
    """A Markdown table (the leaderboards' `md_table`); floats to 3 significant places."""
    return md_table(
        pd.DataFrame([[f"{x:.3g}" if isinstance(x, float) else x for x in row] for row in rows], columns=header)
    )


def committed(*paths: Path) -> str:
    """When the files were last committed (`git log`), or nothing outside a git checkout."""
    names = [str(p.relative_to(ROOT)) for p in paths]
    try:
        done = subprocess.run(
            ["git", "log", "-1", "--format=%h, %cs", "--", *names], cwd=ROOT, capture_output=True, text=True
        )
    except OSError:
        return ""
    if done.returncode or not done.stdout.strip():
        return ""
    return f" Last regenerated in commit {done.stdout.strip()}."


def heading(title: str, source: str, *paths: Path) -> list[str]:
    """A results page's title and the sentence naming what it is rendered from and when that was committed."""
    return [f"# {title}", "", source + committed(*paths)]


def figure(path: Path, alt: str) -> str:
    """An image reference relative to `docs/results/`."""
    if not path.is_file():
        raise FileNotFoundError(f"results figure missing: {path} (run python experiments/regenerate.py)")
    return f"![{alt}](../../{path.relative_to(ROOT).as_posix()})"


def embedded(report: Path, title: str, source: str) -> str:
    """A generated Markdown report under a page title: its headings one level down, its images re-pointed."""
    text = report.read_text()
    text = re.sub(r"^# .*\n", "", text, count=1)

    folder = report.parent.relative_to(ROOT).as_posix()
    text = re.sub(r"\]\(([^/)#:]+\.(?:png|gif))\)", rf"](../../{folder}/\1)", text)
    return "\n".join(heading(title, f"Rendered from `{source}`.", report)) + f"\n\n{text}"


def benchmark() -> str:
    return embedded(BOARDS / "README.md", "Benchmark leaderboard", "leaderboards/README.md")


def prior() -> str:
    return embedded(BOARDS / "prior" / "README.md", "Calibrators with the prior", "leaderboards/prior/README.md")


def montecarlo() -> str:
    """The study's report, then the probe of where each injury moves the load (issue 54, step 9)."""
    page = embedded(
        BOARDS / "montecarlo" / "report.md", "Monte Carlo injury study", "leaderboards/montecarlo/report.md"
    )
    return page + "\n\n" + (BOARDS / "montecarlo" / "injury_load_paths.md").read_text()


def sensitivity(top: int = 6) -> str:
    parts = heading(
        "Sensitivity",
        "Rendered from `leaderboards/sensitivity/*.csv`: the design variables the cost on the calibration trial "
        f"moves most with, {top} per participant (Morris μ*, Sobol total index S_T).",
        BOARDS / "sensitivity",
    )
    for p in PARTICIPANTS:
        morris = pd.read_csv(BOARDS / "sensitivity" / f"sensitivity_{p}_morris.csv").query(
            "output == 'cost' and motion == 'calibrate'"
        )
        sobol = pd.read_csv(BOARDS / "sensitivity" / f"sensitivity_{p}_sobol.csv").query(
            "output == 'cost' and motion == 'calibrate'"
        )
        m = morris.nlargest(top, "mu_star")
        s = sobol.nlargest(top, "ST")
        rows = [
            [a.material, float(a.mu_star), float(a.mu_star_conf), b.material, float(b.ST), float(b.ST_conf)]
            for a, b in zip(m.itertuples(), s.itertuples())
        ]
        header = ["Morris: variable", "μ*", "μ* ± (95 %)", "Sobol: variable", "S_T", "S_T ± (95 %)"]
        parts += [f"\n## {p}\n", table(header, rows), ""]
        parts.append(figure(BOARDS / "sensitivity" / f"sensitivity_{p}_morris.png", f"Morris indices, {p}"))
    return "\n".join(parts) + "\n"


def identifiability() -> str:
    spectrum = pd.read_csv(BOARDS / "identifiability" / "identifiability_spectrum.csv")
    parts = heading(
        "Identifiability",
        "Rendered from `leaderboards/identifiability/identifiability_spectrum.csv`: the Fisher matrix of "
        "the calibration trial at the hidden truth, its directions with a posterior SD under 0.5 Table 2 SD "
        "(what the trial pins), and the best-pinned three.",
        BOARDS / "identifiability",
    ) + [""]
    rows = []
    for p, d in spectrum[spectrum.trials == "calibrate"].groupby("participant"):
        best = d.nsmallest(3, "sd")
        rows.append([p, int((d.sd < 0.5).sum()), len(d), "; ".join(best.leading_materials)])
    parts += [table(["participant", "directions pinned", "of", "best-pinned directions"], rows), ""]
    parts += [figure(BOARDS / "identifiability" / f"identifiability_{p}.png", p) for p in PARTICIPANTS]
    return "\n\n".join(parts) + "\n"


def posterior() -> str:
    parts = [
        "# Bayesian calibration: coverage",
        "",
        "Rendered from `leaderboards/posterior/coverage*.csv`: the share of the 22 material truths inside "
        "the posterior's 50 % and 90 % intervals (well calibrated: 0.5 and 0.9), and the recovery error "
        "(RMS, Table 2 SD) of the posterior mean, the MAP and the population design; means over seeds. "
        "Each study names the commit it was last regenerated in.",
        "",
    ]
    studies = [
        ("coverage.csv", "built-in trials, emcee"),
        ("coverage_model.csv", "the model's own trials, emcee"),
        ("steps1200/coverage_model.csv", "the model's own trials, emcee"),
        ("coverage_model_smc.csv", "the model's own trials, SMC"),
    ]
    cols = ["coverage_50", "coverage_90", "recovery_mean", "recovery_map", "recovery_population"]
    for name, label in studies:
        d = pd.read_csv(BOARDS / "posterior" / name)
        steps = f", {int(d.steps.iloc[0])} steps" if "steps" in d else ""
        rows = [[p, len(g), *(float(g[c].mean()) for c in cols)] for p, g in d.groupby("participant")]
        header = ["participant", "seeds", "50 % coverage", "90 % coverage", "mean", "MAP", "population"]
        # the studies are regenerated one by one (the 1,200-step study spans sessions): each names its commit
        when = committed(BOARDS / "posterior" / name).strip()
        parts += [f"## {label}{steps}", "", *([when, ""] if when else []), table(header, rows), ""]
    parts.append(figure(BOARDS / "posterior" / "posterior_intervals_P1.png", "posterior intervals, P1"))
    return "\n".join(parts) + "\n"


def validation() -> str:
    parts = heading(
        "Validation",
        "Rendered from `experiments/figures/validation_P*.json` (`wrist-bench validate P --json`): each "
        "check of the population design against a published band.",
        *(FIGURES / f"validation_{p}.json" for p in PARTICIPANTS),
    ) + [""]
    reports = {p: json.loads((FIGURES / f"validation_{p}.json").read_text()) for p in PARTICIPANTS}
    first = reports[PARTICIPANTS[0]]["checks"]
    rows = []
    for i, check in enumerate(first):
        cells = []
        for p in PARTICIPANTS:
            c = reports[p]["checks"][i]
            value = "—" if c["value"] is None else f"{c['value']:.3g}"
            cells.append(f"{value} {'✓' if c['passed'] else '✗'}")
        low, high = (math.inf if edge is None else edge for edge in check["band"])  # JSON's None: unbounded
        rows.append([check["description"], f"{band_text(low, high)} {check['unit']}", *cells])
    passed = [sum(c["passed"] for c in reports[p]["checks"]) for p in PARTICIPANTS]
    parts += [table(["check", "band", *PARTICIPANTS], rows), ""]
    parts.append(
        "Passed: " + ", ".join(f"{p} {n} of {len(first)}" for p, n in zip(PARTICIPANTS, passed, strict=True)) + "."
    )
    parts += ["", figure(FIGURES / "validation_P1.png", "validation, P1")]
    return "\n".join(parts) + "\n"


PAGES = {
    "benchmark": benchmark,
    "prior": prior,
    "montecarlo": montecarlo,
    "sensitivity": sensitivity,
    "identifiability": identifiability,
    "posterior": posterior,
    "validation": validation,
}


def render(out: Path) -> list[Path]:
    """Write every results page and its index into `out`."""
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, page in PAGES.items():
        path = out / f"{name}.md"
        path.write_text(page())
        written.append(path)
    index = [
        "# Results",
        "",
        "Every number on these pages is read from a committed results file when the docs "
        "are built; `python experiments/regenerate.py` rewrites those files from real runs.",
        "",
        "```{toctree}",
        ":maxdepth: 1",
        "",
        *PAGES,
        "```",
        "",
    ]
    (out / "index.md").write_text("\n".join(index))
    return written


def setup(app):
    app.connect("builder-inited", lambda app: render(Path(app.srcdir) / "results"))
    return {"parallel_read_safe": True, "version": "1"}
