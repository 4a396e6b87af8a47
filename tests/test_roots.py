"""The bracketed root finder that locates events along a load path."""

import math

import pytest

from bcfem.path.roots import bracketed_root


@pytest.mark.parametrize("f, a, b, root", [
    (lambda x: x**3 - 2 * x - 5, 2.0, 3.0, 2.0945514815423265),  # Newton's classic cubic
    (lambda x: math.cos(x) - x, 0.0, 1.0, 0.7390851332151607),
    (lambda x: math.exp(x) - 1e-3, -10.0, 1.0, math.log(1e-3)),
    (lambda x: (x - 0.3) ** 3, 0.0, 1.0, 0.3),  # a triple root: slow for interpolation
])
def test_known_roots_to_the_tolerance(f, a, b, root):
    for xtol in (1e-6, 1e-12):
        assert abs(bracketed_root(f, a, b, xtol) - root) <= xtol + 1e-15
        assert abs(bracketed_root(f, b, a, xtol) - root) <= xtol + 1e-15  # either order


def test_smooth_functions_take_few_evaluations():
    calls = []

    def f(x):
        calls.append(x)
        return math.tan(x) - 1.0

    root = bracketed_root(f, 0.0, 1.2, 1e-13)
    assert root == pytest.approx(math.pi / 4, abs=1e-13) and len(calls) <= 12


def test_a_jump_is_located_like_bisection():
    """A step function has no root, only a sign change: the bracket around it shrinks to
    the tolerance, and the step count stays within twice bisection's."""
    calls = []

    def f(x):
        calls.append(x)
        return -1.0 if x < 0.123456 else 1.0

    x = bracketed_root(f, 0.0, 1.0, 1e-10)
    assert abs(x - 0.123456) <= 1e-10 and len(calls) <= 2 * math.ceil(math.log2(1e10)) + 2


def test_ends_and_bad_brackets():
    assert bracketed_root(lambda x: x - 1.0, 1.0, 2.0, 1e-12) == 1.0
    with pytest.raises(ValueError, match="do not bracket"):
        bracketed_root(lambda x: x * x + 1, -1.0, 1.0, 1e-12)
