"""Cheap, honest imports: the light modules pull in neither Gymnasium nor the model builder, the
built-in Gymnasium ids are registered whichever of `wrist_env` and `gymnasium` is imported first, and no
library module chooses matplotlib's backend (the application does: wrist-bench sets MPLBACKEND)."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

from wrist_env.cli import COMMANDS

HEAVY = (
    "gymnasium",
    "wrist_env.builder.pipeline",
    "trimesh",
    "igl",
    "numba",
    "scipy",
    "pandas",
    "pyarrow",
    "sklearn",
    "matplotlib",
)


def _run(code: str) -> str:
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return done.stdout.strip()


@pytest.mark.parametrize("module", ["wrist_env.design", "wrist_env.frames", "wrist_env.cost", "optimizers"])
def test_light_modules_import_nothing_heavy(module):
    loaded = _run(f"import sys, {module}; print(' '.join(m for m in {HEAVY!r} if m in sys.modules))")
    assert loaded == "", f"importing {module} imported {loaded}"


def test_running_a_study_loads_no_plotting():
    """A benchmark's or a Monte Carlo study's workers load what runs a calibration (the benchmark, the task, the
    Monte Carlo sampler), not matplotlib: the leaderboard and the figures load when they are written. One process
    for the three (CI's time)."""
    code = (
        "import sys, wrist_env.bench, wrist_env.task, wrist_env.montecarlo.sampler; print('matplotlib' in sys.modules)"
    )
    assert _run(code) == "False"


@pytest.mark.parametrize("order", ["import wrist_env, gymnasium", "import gymnasium, wrist_env"])
def test_builtin_ids_are_registered_in_either_import_order(order):
    ids = _run(f"{order}; print(' '.join(sorted(i for i in gymnasium.registry if i.startswith('wrist_env/'))))")
    assert ids.split() == sorted(
        f"wrist_env/{m}-{p}-v0" for m in ("Calibrate", "Validate", "Idealized") for p in ("P1", "P2", "P3")
    )


def test_no_library_module_chooses_a_matplotlib_backend():
    root = Path(__file__).resolve().parents[1]
    choosers = ("matplotlib.use", "mpl.use", "plt.use", "plt.switch_backend", "matplotlib.pyplot.switch_backend")
    calls = [
        f"{path.relative_to(root)}:{node.lineno}: {ast.unparse(node)}"
        for path in sorted([*(root / "wrist_env").rglob("*.py"), *(root / "optimizers").rglob("*.py")])
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.Call) and ast.unparse(node.func) in choosers
    ]
    assert not calls, calls


@pytest.mark.parametrize("argv", [["--help"], ["no-such-command"]])
def test_the_command_line_answers_without_importing_a_command(argv):
    """`wrist-bench --help` and an unknown command load no command's module, no solver and no builder
    (each command's module is imported when that command is named: `wrist_env.cli.COMMANDS`)."""
    code = (
        "import sys\nfrom wrist_env.cli import main\ntry:\n    main(%r)\nexcept SystemExit:\n    pass\n"
        "print('loaded:', *(m for m in sys.modules if m.startswith('wrist_env.cli.') or m in %r))"
    ) % (argv, HEAVY)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.strip().splitlines()[-1] == "loaded:", done.stdout[-2000:]


def test_every_command_is_declared_by_the_module_the_table_names():
    """`cli.COMMANDS` names, for each command, the module whose `add_commands` declares it (and no
    module declares a command the table lacks)."""
    import argparse
    from importlib import import_module

    from wrist_env.cli import COMMANDS

    for module in sorted({m for m, _ in COMMANDS.values()}):
        declared = []
        import_module(f"wrist_env.cli.{module}").add_commands(
            lambda name, folders_option=True, **kw: declared.append(name) or argparse.ArgumentParser()
        )
        assert sorted(declared) == sorted(n for n, (m, _) in COMMANDS.items() if m == module), module


@pytest.mark.parametrize("command", COMMANDS)
def test_a_commands_help_and_usage_errors_load_nothing_it_runs(command):
    """`wrist-bench <command> --help` exits 0 and `wrist-bench <command> --no-such-option` exits 2 having
    imported none of `HEAVY` and no module of `wrist_env.cli.run`: a command's declaring module imports only
    light ones, and `main` imports its run module once the arguments have parsed (issue 52)."""
    code = (
        "import sys\nfrom wrist_env.cli import main\nfor option in ('--help', '--no-such-option'):\n"
        "    try:\n        print('status:', main([%r, option]))\n    except SystemExit as exit:\n"
        "        print('status:', exit.code)\n"
        "print('loaded:', *(m for m in sys.modules if m.startswith('wrist_env.cli.run') or m in %r))"
    ) % (command, HEAVY)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    lines = done.stdout.strip().splitlines()
    assert [line for line in lines if line.startswith("status:")] == ["status: 0", "status: 2"], done.stderr[-2000:]
    assert lines[-1] == "loaded:", lines[-1]


def test_every_command_runs_a_function_of_a_run_module():
    """Each command's `run` default names ("module:function") a function of `wrist_env.cli.run` that
    `main` resolves after parsing."""
    from pkgutil import resolve_name

    from wrist_env.cli import parser

    sub = next(a for a in parser()._actions if a.dest == "command")
    assert sorted(sub.choices) == sorted(COMMANDS)
    for name, command in sub.choices.items():
        run = resolve_name(f"wrist_env.cli.run.{command.get_default('run')}")
        assert callable(run) and run.__module__.startswith("wrist_env.cli.run."), name


def test_a_shipped_model_loads_without_the_builder():
    """`registry.load_model` of a built-in participant reads its shipped model (or the cache) without
    importing the builder (scikit-learn, the morph): the builder only on a cache miss."""
    loaded = _run(
        "import sys\nfrom wrist_env.participants.registry import load_model\nload_model('P1')\n"
        "print(' '.join(m for m in ('wrist_env.builder.pipeline', 'sklearn') if m in sys.modules))"
    )
    assert loaded == "", loaded


ROOT = Path(__file__).resolve().parents[1]
STUDIES = (
    "wrist_env.bench",
    "wrist_env.montecarlo",
    "wrist_env.identification",
    "wrist_env.validation",
    "wrist_env.participants",
    "wrist_env.envs",
    "wrist_env.cli",
    "wrist_env.task",
    "wrist_env.runs",
    "wrist_env.anatomy",
    "wrist_env.builder",
    "wrist_env.solver",
)
"""What a figure may not import: the studies, the participants, the environments, the shell, and the floors that
load, build or simulate a model (anatomy, builder, solver). Everything below them (the vocabulary: `design`,
`frames`, `cost`, `trial`, `model`, `motions`, `io`, `errors`, `limits`), `wrist_env.figures` itself and
third-party libraries are allowed."""


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(p): p for p in sorted((ROOT / "wrist_env").rglob("*.py"))}


def _imported(node: ast.Import | ast.ImportFrom, module: str) -> list[str]:
    """The project modules an import statement runs: each named module (a `from` name that is a module, else
    the package it is taken from) and the packages above it."""
    if isinstance(node, ast.Import):
        names = [a.name for a in node.names]
    else:
        base = node.module or ""
        if node.level:
            package = module.split(".")[: -1 if MODULES[module].name != "__init__.py" else None]
            base = ".".join(package[: len(package) - node.level + 1] + ([base] if base else []))
        names = [f"{base}.{a.name}" if f"{base}.{a.name}" in MODULES else base for a in node.names]
    parts = [n.split(".") for n in names if n.split(".")[0] == "wrist_env"]
    return sorted({".".join(p[:i]) for p in parts for i in range(1, len(p) + 1)} & set(MODULES))


def _imports(module: str) -> tuple[set[str], list[tuple[str, int, list[str]]]]:
    """(the project modules `module` imports when it loads: at top level, outside `if TYPE_CHECKING:`, and its
    own packages; [(function, line, modules)] of the imports inside its functions)."""
    top, local = {".".join(module.split(".")[:i]) for i in range(1, module.count(".") + 1)}, []

    def walk(body, function):
        for node in body:
            if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
                continue
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                found = _imported(node, module)
                if function is None:
                    top.update(found)
                elif found:
                    local.append((function, node.lineno, found))
            inner = node.name if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) else function
            for field in ("body", "orelse", "finalbody", "handlers"):
                if isinstance(getattr(node, field, None), list):
                    walk(getattr(node, field), inner)

    walk(ast.parse(MODULES[module].read_text()).body, None)
    return top - {module}, local


def test_no_figure_imports_a_study():
    """Pictures take data (issue 56): a module of `wrist_env.figures` imports none of `STUDIES`, at top level or
    inside a function; what it draws is computed by the study or command that asks for it and handed over as
    arrays, frames or frozen dataclasses of them."""
    found = []
    for module, path in MODULES.items():
        if module != "wrist_env.figures" and not module.startswith("wrist_env.figures."):
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for name in _imported(node, module):
                    study = next((s for s in STUDIES if name == s or name.startswith(s + ".")), None)
                    if study:
                        found.append(f"{module}:{node.lineno} imports {name}")
    assert not found, found


def test_no_function_local_import_hides_a_cycle():
    """A project import inside a function is allowed for lazy loading (Numba, the solver, a command's work), not to
    hide a cycle: it fails when the module it imports already imports, transitively at top level, the importing
    module (a package importing its own submodule lazily is not a cycle: the package always loads first)."""
    graph = {m: _imports(m) for m in MODULES}

    def reach(start: str) -> set[str]:
        seen, todo = set(), [start]
        while todo:
            for m in graph[todo.pop()][0] - seen:
                seen.add(m)
                todo.append(m)
        return seen

    cycles = [
        f"{module}:{line} ({function}) imports {target}, which imports {module}"
        for module, (_, local) in graph.items()
        for function, line, targets in local
        for target in targets
        if not target.startswith(module + ".") and target != module and module in reach(target)
    ]
    assert not cycles, cycles


def test_the_ligament_catalogue_is_imported_from_its_owner():
    """One owner per concept (issue 56): every name of the ligament catalogue (`wrist_env.ligaments.__all__`) is
    imported from `wrist_env.ligaments`, nowhere from `wrist_env.design`, which builds the design on it and no
    longer re-exports it (package, tests, experiments and docs examples alike)."""
    from wrist_env import ligaments

    catalogue = set(ligaments.__all__)
    found = []
    for path in sorted(ROOT.rglob("*.py")):
        if any(
            part in {"runs", ".git", "build", "_build"} or part.startswith(".")
            for part in path.parts[len(ROOT.parts) :]
        ):
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module == "wrist_env.design":
                found += [f"{path.relative_to(ROOT)}:{node.lineno} {a.name}" for a in node.names if a.name in catalogue]
    assert not found, found
    from wrist_env import design

    assert not catalogue & set(design.__all__)


def _defined(path: Path) -> set[str]:
    """The names a script defines or imports at its top level (read, not run)."""
    names = set()
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names.update(n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name))
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split(".")[0] for a in node.names)
    return names


def test_every_experiment_imports_names_that_exist():
    """The experiment scripts are run by hand or by `experiments/regenerate.py`, not by the tests: each name one
    imports from the package or from a sibling script must still be there (a script that imported three names
    moved out of `make_trials.py` failed only when regenerate reached it, hours into a run). Read, not run: the
    package's modules are imported, the sibling scripts parsed."""
    import importlib

    scripts = {p.stem: p for p in (ROOT / "experiments").rglob("*.py")}
    missing = []
    for path in scripts.values():
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom) or node.level or not node.module:
                continue
            top = node.module.split(".")[0]
            if top in ("wrist_env", "optimizers"):
                module = importlib.import_module(node.module)
                missing += [
                    f"{path.relative_to(ROOT)}:{node.lineno} {node.module}.{a.name}"
                    for a in node.names
                    if not hasattr(module, a.name)
                    and not (ROOT / Path(*node.module.split("."), a.name)).exists()
                    and not (ROOT / Path(*node.module.split("."), f"{a.name}.py")).exists()
                ]
            elif node.module in scripts:
                there = _defined(scripts[node.module])
                missing += [
                    f"{path.relative_to(ROOT)}:{node.lineno} {node.module}.{a.name}"
                    for a in node.names
                    if a.name not in there
                ]
    assert len(scripts) >= 25
    assert not missing, missing
