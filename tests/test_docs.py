"""The README is one screen and its examples run; the docs site builds with warnings as errors, and its
results pages carry the committed results files' numbers; the hand-written pages type no result of our runs
(those are the results pages', rendered, or the dated development notes')."""

import json
import re
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
    """The site built afresh with warnings as errors; every gallery example run again (sphinx-gallery would
    skip one whose source is unchanged since the last build in docs/auto_examples/), an example that raises
    failing the build."""
    out = tmp_path_factory.mktemp("site")
    done = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-E", "-q", "-b", "html",
         "-D", "sphinx_gallery_conf.run_stale_examples=1", str(ROOT / "docs"), str(out)],
        capture_output=True,
        text=True,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-4000:]
    return out


def test_the_docs_build_without_warnings(site):
    pages = ("index", "getting-started", "extending", "solver", "benchmark", "api", "results/index")
    for page in (*pages, "results/validation", "auto_examples/index"):
        assert (site / f"{page}.html").is_file(), page


EXAMPLES = sorted((ROOT / "docs" / "examples").glob("plot_*.py"))


def test_there_are_gallery_examples():
    assert len(EXAMPLES) >= 5, EXAMPLES


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_every_gallery_example_ran_in_the_build_and_shows_its_figures(site, example):
    """Each docs/examples/plot_*.py is a page of the built gallery, linked from its index, executed in this build
    (sphinx-gallery writes its running time) and showing the figures it drew."""
    page = site / "auto_examples" / f"{example.stem}.html"
    assert page.is_file(), f"{example.name} is not in the built gallery"
    assert f'href="{example.stem}.html' in (site / "auto_examples" / "index.html").read_text()
    html = page.read_text()
    assert "Total running time of the script" in html
    figures = sorted((site / "_images").glob(f"sphx_glr_{example.stem}_0*.png"))
    assert figures and all(f.name in html for f in figures), f"{example.name}: no figure on its page"


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


def test_the_posterior_page_dates_each_study_by_its_own_commit(site):
    """The studies are regenerated one at a time: each section names the commit of its own table."""
    text = (site / "results" / "posterior.html").read_text()
    sections = text.split("<h2")[1:]
    tables = ["coverage.csv", "coverage_model.csv", "steps1200/coverage_model.csv", "coverage_model_smc.csv"]
    assert len(sections) == len(tables)
    for section, name in zip(sections, tables, strict=True):
        done = subprocess.run(
            ["git", "log", "-1", "--format=%h", "--", f"leaderboards/posterior/{name}"],
            cwd=ROOT, capture_output=True, text=True, check=True,
        )  # fmt: skip
        assert f"Last regenerated in commit {done.stdout.strip()}," in section, name


def test_the_sensitivity_page_ranks_the_calibration_trials_own_indices(site):
    import pandas as pd

    page = (ROOT / "docs" / "results" / "sensitivity.md").read_text()  # rendered by the build (`site`)
    p1 = page.split("## P1")[1].split("## P2")[0]
    rows = [line.split("|")[1:3] for line in p1.splitlines() if line.startswith("| ") and "variable" not in line]
    morris = pd.read_csv(ROOT / "leaderboards" / "sensitivity" / "sensitivity_P1_morris.csv")
    top = morris.query("output == 'cost' and motion == 'calibrate'").nlargest(len(rows), "mu_star")
    assert [(m.strip(), v.strip()) for m, v in rows] == [(r.material, f"{r.mu_star:.3g}") for r in top.itertuples()]


def test_the_identifiability_page_counts_the_calibration_trials_directions(site):
    import pandas as pd

    page = (ROOT / "docs" / "results" / "identifiability.md").read_text()  # rendered by the build (`site`)
    p1 = next(line.split("|")[1:4] for line in page.splitlines() if line.startswith("| P1 "))
    spectrum = pd.read_csv(ROOT / "leaderboards" / "identifiability" / "identifiability_spectrum.csv")
    calibrate = spectrum.query("participant == 'P1' and trials == 'calibrate'")
    assert [c.strip() for c in p1] == ["P1", str(int((calibrate.sd < 0.5).sum())), str(len(calibrate))]


DOCS = ROOT / "docs"
HISTORY = DOCS / "history.md"
NARRATIVE = sorted(p for p in DOCS.glob("*.md") if p != HISTORY)  # results/ is rendered, not hand-written
# The ways a measured result of our own runs gets typed into prose. Inputs are not caught: literature values,
# bands, Table 1-2 values, defaults and test tolerances carry no such phrasing (a timing of a run, a rate, a
# speed-up, a pass count, a coverage, a cost or recovery figure, R-hat, a "(measured)" section).
RESULT_KINDS = {
    "a timing": r"(?<![\w.-])\d+(?:[.,]\d+)*\s?(?:ms|µs|min|s)\b",
    "a rate": r"\d\s*(?:simulations|runs|evaluations|sweeps|trials)/s\b",
    "a speed-up or step ratio": r"(?<![≥≤<>] )(?<![\d.])\d+(?:\.\d+)?×\s+(?:fewer|faster|slower)\b",
    "a pass count": r"\bpass(?:es|ed)?\s+\d+(?:–\d+)?\s+of\s+\d+|\b\d+(?:–\d+)?\s+of\s+\d+\s+checks\b",
    "a coverage": r"\b(?:coverage|intervals? hold(?:s|ing)?)\b[^.\n]{0,40}?\d+(?:\.\d+)?\s?%",
    "a cost or a recovery error": r"\b(?:costs?|recovery(?: error)?)\s+(?:of\s+)?\d+\.\d{2,}",
    "an R-hat": r"R̂\s*(?:=\s*)?\d+\.\d+",
    "a measured section": r"^#{1,6} .*\bmeasured\b",
}


def typed_results(text: str) -> list[str]:
    """Each phrase of the text that reads as a measured result, with its kind."""
    return [
        f"{kind}: {m.group(0)!r}"
        for kind, pattern in RESULT_KINDS.items()
        for m in re.finditer(pattern, text, flags=re.MULTILINE)
    ]


def test_the_result_patterns_catch_what_the_old_pages_typed():
    old = [
        "took **19.1 min** on this 2-core machine at commit ca56483 (25,266 runs, 22.1 runs/s",
        "the sweep, 3.8× fewer steps than --solver default",
        "done; the default model passes 7–8 of 13 checks",
        "coverage 32 % / 77 % against 27 % / 77 % at 300 steps",
        "on P1's calibration trial: cost 1.14 at truth, 3.56 at the population means",
        "split R̂ 1.28 (300 steps: 3.19)",
        "### Speed (measured)",
    ]
    assert [len(typed_results(line)) > 0 for line in old] == [True] * len(old)
    inputs = [
        "Rainbow 2013 (46 % / 42 %)",
        "semi-implicit Euler at a fixed step (6e-5 s) with mass scaling",
        "net force ≤ 0.1 % of the largest bundle force and at least 0.01 N",
        "in at most 1/2.5 of their steps; a 10× tighter equilibrium tolerance",
        "Every test has a 20-minute timeout (pytest-timeout)",
        "the preprint's mean RS pressure (Table 5's normalizer) is 0.65 MPa",
    ]
    assert [typed_results(line) for line in inputs] == [[]] * len(inputs)


@pytest.mark.parametrize("page", NARRATIVE, ids=lambda p: p.name)
def test_a_narrative_page_types_no_measured_result(page):
    found = typed_results(page.read_text())
    assert not found, (
        f"{page.name} types measured results by hand: {found}. Link the results page that renders them "
        "(docs/_ext/results.py), or move them, with their commit, to docs/history.md"
    )


def test_the_development_notes_are_in_the_site_and_dated():
    index = (DOCS / "index.md").read_text()
    toctrees = re.findall(r"```\{toctree\}(.*?)```", index, flags=re.DOTALL)
    assert any(re.search(r"^history$", tree, flags=re.MULTILINE) for tree in toctrees)
    text = HISTORY.read_text()
    assert "not regenerated" in text.split("\n## ")[0] and "results/index.md" in text.split("\n## ")[0]
    sections = text.split("\n## ")[1:]
    assert len(sections) >= 10
    commit = re.compile(r"\b(?=[0-9a-f]*\d)(?=[0-9a-f]*[a-f])[0-9a-f]{7,40}\b")
    undated = [s.splitlines()[0] for s in sections if not commit.search(s.split("\n\n")[1])]
    assert not undated, f"sections whose first paragraph names no commit: {undated}"
    hashes = sorted(set(commit.findall(text)))
    done = subprocess.run(
        ["git", "cat-file", "--batch-check"], input="\n".join(hashes) + "\n", cwd=ROOT, capture_output=True, text=True
    )
    if done.returncode:  # not a git checkout (an installed copy)
        pytest.skip("no git history to check the commits against")
    missing = [h for h, line in zip(hashes, done.stdout.splitlines()) if line.endswith("missing")]
    assert not missing, f"docs/history.md names commits this repository does not have: {missing}"


def _layout_entries(block: str) -> set[str]:
    """The paths the layout page's tree names: a line is an entry, indented two spaces a level, a folder
    ending in "/"."""
    entries, parents = set(), []
    for line in block.splitlines():
        if not line.strip():
            continue
        depth = (len(line) - len(line.lstrip(" "))) // 2
        name = line.split()[0]
        parents = parents[:depth] + [name.rstrip("/")]
        if not name.endswith("/"):
            entries.add("/".join(parents))
    return entries


def test_the_layout_page_names_every_module_and_no_other():
    """docs/layout.md lists every module of `wrist_env` and `optimizers` (package `__init__`s but the top one
    aside), and nothing that is not there."""
    block = (ROOT / "docs" / "layout.md").read_text().split("```")[1]
    listed = {e for e in _layout_entries(block) if e.split("/")[0] in ("wrist_env", "optimizers")}
    tree = {
        p.relative_to(ROOT).as_posix()
        for package in ("wrist_env", "optimizers")
        for p in (ROOT / package).rglob("*.py")
        if p.name != "__init__.py" or p.parent.name == "wrist_env"
    }
    assert listed == tree, {"not listed": sorted(tree - listed), "listed, not there": sorted(listed - tree)}


EXTENDING = DOCS / "extending.md"
CODE_PATH = r"(?:wrist_env|optimizers|tests|experiments)/[\w./-]+"


def test_the_extending_page_names_only_files_and_names_that_exist():
    """Every path the Extending page names is in the tree, and every `NAME` it places "in `path`" is in that
    file: the walk-throughs follow the code when it moves."""
    text = EXTENDING.read_text()
    paths = set(re.findall(rf"`({CODE_PATH})`", text))
    assert len(paths) >= 30, sorted(paths)
    missing = sorted(p for p in paths if not (ROOT / p).exists())
    assert not missing, f"docs/extending.md names paths that do not exist: {missing}"
    placed = re.findall(rf"`(\w+)`\s+in\s+`({CODE_PATH}\.py)`", text)
    assert len(placed) >= 8, placed
    absent = [(name, path) for name, path in placed if not re.search(rf"\b{name}\b", (ROOT / path).read_text())]
    assert not absent, f"docs/extending.md places names in files that do not hold them: {absent}"


def _docstrings(path: Path):
    import ast

    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str):
            yield node.value.value  # docstrings of modules, classes, functions and attributes alike


def test_no_docstring_writes_a_model_count_as_a_literal_shape():
    """A shape of the model's bodies or contact pairs is written in symbols (`n_bodies`, `n_pairs`: defined in
    `wrist_env.model`'s docstring), not in today's counts, which went stale as bodies were added: a tuple
    with a comma whose first entry, or the first after one leading symbol, is the count ("(7, 3)",
    "(n_frames, 7, 4, 4)", "(10,)"). A doctest's printed output ("(5, 7, 4, 4)") leads with a number and
    passes."""
    from wrist_env.model import BONES, PAIRS

    found = []
    for count, symbol in ((len(BONES), "n_bodies"), (len(PAIRS), "n_pairs")):
        shape = re.compile(rf"\((?:[a-z_]+, )?{count}(?:, \d+)*,?\)")
        for top in ("wrist_env", "optimizers"):
            for path in sorted((ROOT / top).rglob("*.py")):
                for doc in _docstrings(path):
                    found += [
                        f"{path.relative_to(ROOT)}: {m.group()} (write {symbol})"
                        for m in shape.finditer(doc)
                        if "," in m.group()
                    ]
    assert not found, "shapes written in today's counts:\n" + "\n".join(found)


NUMPYDOC_CHECKED = {
    "GL08": "no docstring",
    "SS01": "no one-line summary",
    "SS03": "the summary does not end with a period",
    "SS06": "the summary does not fit on one line",
    "PR01": "a parameter not documented",
    "PR02": "a documented parameter the signature does not have",
    "PR03": "the parameters documented in another order than the signature's",
    "PR04": "a parameter without its type",
    "PR05": "a parameter's type ending with a period",
    "PR06": 'a type written "integer", "boolean" or "string"',
    "PR07": "a parameter without a description",
    "PR10": "no space before the colon after a parameter's name",
    "RT01": "no Returns section in a function that returns something",
    "RT03": "a return value without a description",
    "YD01": "no Yields section in a generator",
}
"""The numpydoc validation codes the public API is held to (`numpydoc.validate.ERROR_MSGS`). Not checked:
ES01 (an extended summary: many one-line summaries say all), EX01 (an Examples section: most entry points build
a model or simulate, which takes minutes; a doctest is given where one runs fast), SA01-SA04 (a See Also
section), SS05 (a summary starting with an infinitive verb: the summaries here are noun phrases, "The Gymnasium
id of a participant's motion.", as much of the code's are), SS02, PR08, PR09, RT04, RT05 (capitals and final
periods of descriptions: prose style, not content), GL01, GL02 (where the quotes sit: ruff format's), GL06,
GL07 (sections numpydoc does not know, and their order: the env's docstring has Gymnasium's, rendered by
napoleon's custom sections, docs/conf.py)."""
_ERROR_BASES = (BaseException,)


def public_api() -> list[tuple[str, object]]:
    """Every function and class named in the `__all__` of a module of `wrist_env` or `optimizers` (a package's
    `__init__` or any other module declaring its own), but `wrist_env.solver`'s and its submodules' (the
    kernels' own docstrings: shapes in symbols, their own tests), once each, by the qualified name of where it
    is defined."""
    import importlib
    import inspect

    found = {}
    for top in ("wrist_env", "optimizers"):
        for path in sorted((ROOT / top).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            if name == "wrist_env.solver" or name.startswith("wrist_env.solver."):
                continue
            if "__all__" not in path.read_text():
                continue  # not imported: a module without `__all__` adds no name
            module = importlib.import_module(name)
            for public in getattr(module, "__all__", ()):
                obj = getattr(module, public)
                if inspect.isfunction(obj) or inspect.isclass(obj):
                    found.setdefault(f"{obj.__module__}.{obj.__qualname__}", obj)
    return sorted(found.items())


def test_the_public_api_has_numpydoc_sections():
    """Each public function and class (`public_api`: every module's `__all__`, not only the packages') passes
    numpydoc's validation on the codes of `NUMPYDOC_CHECKED`: a parameter added without documenting it, or a
    function that returns without a Returns section, fails here. An exception (`*Error`) needs only its
    docstring's summary (GL08, SS01, SS03, SS06)."""
    from numpydoc.validate import validate

    api = public_api()
    assert len(api) >= 140, [name for name, _ in api]
    failures = []
    for name, obj in api:
        codes = set(NUMPYDOC_CHECKED)
        if isinstance(obj, type) and issubclass(obj, _ERROR_BASES):
            codes = {"GL08", "SS01", "SS03", "SS06"}
        failures += [f"{name}: {code} {message}" for code, message in validate(name)["errors"] if code in codes]
    assert not failures, "docstrings short of the numpydoc sections:\n" + "\n".join(failures)
