"""Events inside an accepted arc-length step: the root of an event function, and a fold
(where the tangent's load component vanishes), located on the step's hyperplanes."""

from __future__ import annotations

import math

from bcfem.path.branch import ContinuationError, LimitPoint
from bcfem.path.roots import bracketed_root


def locate(arc, problem, base, tangent, ds: float, f_now, f0: float, f1: float) -> float:
    """Root in (0, ds) of ``f_now`` along the hyperplanes of ``arc`` (an
    :class:`~bcfem.path.continuation.ArcLength`) from ``base``; states end at the root."""

    def f(sigma):
        if sigma <= 0:
            return f0
        if sigma >= ds:
            return f1
        if not arc._solve_at(problem, base, tangent, sigma):
            raise ContinuationError(f"Newton failed inside an accepted step (sigma={sigma:g})")
        value = f_now()
        if not math.isfinite(value):
            raise ContinuationError(f"the located function is not finite inside a step (sigma={sigma:g})")
        return value

    try:
        sigma = bracketed_root(f, 0.0, ds, xtol=arc.params.event_tol)
        if not arc._solve_at(problem, base, tangent, sigma):
            raise ContinuationError(f"Newton failed at a located event (sigma={sigma:g})")
        return sigma
    except ContinuationError:
        # Newton cannot reach points inside the step (a kink of a contact's branch): the
        # event is the step's end, located to within the step only
        arc.unlocated += 1
        if not arc._solve_at(problem, base, tangent, ds):
            raise ContinuationError(f"Newton failed again at an accepted step's end (ds={ds:g})") from None
        return ds

def locate_fold(arc, problem, base, tangent, ds: float, s: float, observe, f1: float) -> LimitPoint:
    """The point in (0, ds) where the tangent's load component vanishes."""
    il = arc._index(problem)[1]
    f0 = float(tangent[il][0])
    sigma = locate(arc, problem, base, tangent, ds,
                         lambda: float(arc._tangent(problem)[il][0]), f0, f1)
    values = observe()
    values["s"] = s + sigma
    return LimitPoint(kind="max" if f0 > 0 else "min", s=s + sigma, values=values)
