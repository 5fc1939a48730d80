"""The public names: every package, and every module that is an entry point of the API, declares
`__all__`; every name in it exists and is public, `from X import *` gives exactly those names, and an
entry-point module lists everything public it defines (a name added without its `__all__` line fails)."""

import ast
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = sorted(
    ".".join(p.parent.relative_to(ROOT).parts)
    for top in ("wrist_env", "optimizers")
    for p in (ROOT / top).rglob("__init__.py")
)
ENTRY_MODULES = (
    "wrist_env.task",
    "wrist_env.design",
    "wrist_env.frames",
    "wrist_env.cost",
    "wrist_env.trial",
    "wrist_env.model",
    "wrist_env.io",
    "wrist_env.errors",
    "optimizers.base",
    "optimizers.registry",
)


def _path(module: str) -> Path:
    path = ROOT.joinpath(*module.split("."))
    return path / "__init__.py" if path.is_dir() else path.with_suffix(".py")


def _declares_all(module: str) -> bool:
    for node in ast.parse(_path(module).read_text()).body:
        targets = (
            node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
        )
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
            return True
    return False


def _defined_public(module: str) -> set[str]:
    """The public names a module's own top level defines (functions, classes, assignments), not imports."""
    names = set()
    for node in ast.parse(_path(module).read_text()).body:
        if isinstance(node, ast.FunctionDef | ast.ClassDef):
            names.add(node.name)
        elif isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names |= {n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)}
    return {n for n in names if not n.startswith("_")}


def test_the_packages_are_found():
    assert "wrist_env" in PACKAGES and "optimizers" in PACKAGES and "wrist_env.solver" in PACKAGES


@pytest.mark.parametrize("module", PACKAGES + list(ENTRY_MODULES))
def test_declares_all_of_existing_public_names(module):
    assert _declares_all(module), f"{_path(module).relative_to(ROOT)} declares no __all__"
    mod = importlib.import_module(module)
    assert len(set(mod.__all__)) == len(mod.__all__), f"{module}.__all__ repeats a name"
    private = [n for n in mod.__all__ if n.startswith("_")]
    assert not private, f"{module}.__all__ lists private names {private}"
    missing = [n for n in mod.__all__ if not hasattr(mod, n)]
    assert not missing, f"{module}.__all__ lists names it does not have: {missing}"
    namespace: dict = {}
    exec(f"from {module} import *", namespace)
    assert set(namespace) - {"__builtins__"} == set(mod.__all__)


@pytest.mark.parametrize("module", ENTRY_MODULES)
def test_an_entry_module_lists_all_it_defines(module):
    unlisted = _defined_public(module) - set(importlib.import_module(module).__all__)
    assert not unlisted, f"{module} defines public names not in its __all__: {sorted(unlisted)}"


MAX_MODULE_LINES = 400
"""Small modules (issue 56): a module of the package or the calibrators past this many lines holds more than
one concept; split it by concept rather than trimming it to pass."""


def test_no_module_is_over_the_line_limit():
    lines = {
        str(path.relative_to(ROOT)): len(path.read_text().splitlines())
        for folder in ("wrist_env", "optimizers")
        for path in (ROOT / folder).rglob("*.py")
    }
    assert lines and not {p: n for p, n in lines.items() if n > MAX_MODULE_LINES}
