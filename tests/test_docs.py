"""The README is one screen and its examples run; the docs site builds with warnings as errors, and its
results pages carry the committed results files' numbers."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

import wrist_env

ROOT = Path(wrist_env.__file__).resolve().parent.parent
README = ROOT / "README.md"


def python_blocks(page: Path) -> list[str]:
    return [block.split("```")[0] for block in page.read_text().split("```python\n")[1:]]


def test_the_readme_is_one_screen_and_shows_both_examples():
    assert len(README.read_text().splitlines()) <= 150
    blocks = python_blocks(README)
    assert any("gym.make(" in b for b in blocks) and any("calibrate(" in b for b in blocks)


@pytest.mark.slow
def test_the_readme_examples_run(built, tmp_path, monkeypatch, capsys):
    built("P1")
    built("P3")
    monkeypatch.chdir(tmp_path)
    for code in python_blocks(README):
        exec(compile(code, str(README), "exec"), {})
    out = capsys.readouterr().out
    assert "reward -" in out and "recovery " in out


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    done = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-E", "-q", "-b", "html", str(ROOT / "docs"), str(out)],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr[-4000:]
    return out


def test_the_docs_build_without_warnings(site):
    for page in ("index", "getting-started", "solver", "benchmark", "api", "results/index", "results/validation"):
        assert (site / f"{page}.html").is_file(), page


def test_a_results_page_shows_the_committed_numbers(site):
    html = (site / "results" / "validation.html").read_text()
    for participant in ("P1", "P2", "P3"):
        record = json.loads((ROOT / "experiments" / "figures" / f"validation_{participant}.json").read_text())
        ratio = next(c for c in record["checks"] if c["id"] == "rs_rl_force_ratio")
        assert f"{ratio['value']:.3g} " in html
    board = (site / "results" / "benchmark.html").read_text()
    population = next(
        line
        for line in (ROOT / "leaderboards" / "README.md").read_text().splitlines()
        if line.startswith("| *population design*")
    )
    for cost in population.split("|")[2:-1]:
        assert cost.strip() in board


def test_the_sensitivity_page_ranks_the_calibration_trials_own_indices(site):
    import pandas as pd

    page = (ROOT / "docs" / "results" / "sensitivity.md").read_text()  # rendered by the build (`site`)
    p1 = page.split("## P1")[1].split("## P2")[0]
    rows = [line.split("|")[1:3] for line in p1.splitlines() if line.startswith("| ") and "variable" not in line]
    morris = pd.read_csv(ROOT / "leaderboards" / "sensitivity" / "sensitivity_P1_morris.csv")
    top = morris.query("output == 'cost' and motion == 'calibrate'").nlargest(len(rows), "mu_star")
    assert [(m.strip(), v.strip()) for m, v in rows] == [(r.material, f"{r.mu_star:.3g}") for r in top.itertuples()]
