"""Fixtures of the solver tests."""

import pytest


@pytest.fixture(scope="module")
def p1(built):
    """The built participant P1 (the shipped model)."""
    return built("P1")
