"""A bracketed scalar root, for locating events along a load path.

Chandrupatla's method (1997): inverse quadratic interpolation when the last three
points allow it, bisection otherwise, so it keeps a bracket, converges
superlinearly on smooth functions and never needs more than about twice the
bisection count. It replaces ``scipy.optimize.brentq`` on the solve path, whose
import costs more than a whole small solve.
"""

from __future__ import annotations

import math
from collections.abc import Callable


def bracketed_root(f: Callable[[float], float], a: float, b: float, xtol: float, rtol: float = 4e-16,
                   max_iterations: int = 200) -> float:
    """A root of ``f`` in [a, b], where f(a) and f(b) differ in sign (or one is zero), to
    ``xtol + rtol |x|``.

    Raises:
        ValueError: if f(a) and f(b) have the same sign.
    """
    fa, fb = f(a), f(b)
    if fa == 0:
        return a
    if fb == 0:
        return b
    if math.copysign(1, fa) == math.copysign(1, fb):
        raise ValueError(f"f({a:g}) = {fa:g} and f({b:g}) = {fb:g} do not bracket a root")
    c, fc = a, fa
    t = 0.5
    for _ in range(max_iterations):
        x = a + t * (b - a)
        fx = f(x)
        if fx == 0:
            return x
        if math.copysign(1, fx) == math.copysign(1, fa):
            c, fc = a, fa
        else:
            c, fc = b, fb
            b, fb = a, fa
        a, fa = x, fx
        # the best point so far, and the half-width of the bracket in units of |b - a|
        best = a if abs(fa) < abs(fb) else b
        tol = 2 * rtol * abs(best) + 0.5 * xtol
        tl = tol / abs(b - a)
        if tl > 0.5:
            return best
        xi = (a - b) / (c - b)
        phi = (fa - fb) / (fc - fb)
        if phi**2 < xi and (1 - phi) ** 2 < 1 - xi:  # inverse quadratic interpolation is safe
            t = fa / (fb - fa) * fc / (fb - fc) + (c - a) / (b - a) * fa / (fc - fa) * fb / (fc - fb)
        else:
            t = 0.5
        t = min(1 - tl, max(tl, t))
    raise RuntimeError(f"no root to {xtol:g} in {max_iterations} iterations")
