"""`wrist_env.limits`: the rules every size and value a user types is checked by (issue 53)."""

import argparse
import ast
import math
from pathlib import Path

import pytest

from wrist_env import limits
from wrist_env.errors import InputError
from wrist_env.limits import bounded_float, bounded_int, check_float


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, True, "3", None, -0.5, 1000.5])
def test_check_float_refuses_what_is_not_a_finite_number_in_range(value):
    with pytest.raises(InputError, match=r"load must be a finite number in \[0, 1,000\] \(N\), but got "):
        check_float("load", value, 0.0, 1000.0, "N")


def test_check_float_takes_ints_and_floats_at_the_ends_of_the_range():
    assert check_float("x", 0, 0.0, 1.0) == 0.0 and isinstance(check_float("x", 1, 0.0, 1.0), float)


@pytest.mark.parametrize(
    "kind, text, says",
    [
        (bounded_int("frames", 1, 10), "11", "frames must be an integer in [1, 10], but got 11"),
        (bounded_int("frames", 1, 10), "1e8", "frames must be an integer in [1, 10], but got '1e8'"),
        (bounded_float("angle", -90.0, 90.0), "nan", "angle must be a finite number in [-90, 90], but got nan"),
        (bounded_float("angle", -90.0, 90.0), "ten", "angle must be a finite number in [-90, 90], but got 'ten'"),
    ],
)
def test_the_argparse_types_give_the_rule_and_the_value(kind, text, says):
    with pytest.raises(argparse.ArgumentTypeError) as refused:
        kind(text)
    assert str(refused.value) == says


def test_the_argparse_types_parse_what_is_in_bounds():
    assert bounded_int("n", 1, 10)("10") == 10 and bounded_float("x", 0.0, 1.0)("0.25") == 0.25


def test_every_limit_says_why():
    """Each MAX_/MIN_ constant of limits.py is followed by its docstring (why that bound)."""
    body = ast.parse(Path(limits.__file__).read_text()).body
    names = [
        (node.targets[0].id, body[i + 1] if i + 1 < len(body) else None)
        for i, node in enumerate(body)
        if isinstance(node, ast.Assign) and node.targets[0].id.startswith(("MAX_", "MIN_"))
    ]
    assert len(names) >= 20
    bare = [n for n, after in names if not (isinstance(after, ast.Expr) and isinstance(after.value, ast.Constant))]
    assert not bare, bare
