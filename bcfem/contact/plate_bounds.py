"""Frictionless contact with the rigid plate z = 0 as bounds of a variational-inequality SNES."""

from __future__ import annotations

import numpy as np
from dolfinx import fem


def plate_bounds(problem, dofs: np.ndarray, heights: np.ndarray, name: str = "displacement") -> None:
    """z = Z + u_z >= 0 at the displacement's local dofs ``dofs`` (their u_z entries), of reference
    heights ``heights``: u_z >= -Z there; every other unknown of ``problem`` is free."""
    lower = [fem.Function(s.function_space) for s in problem.states]
    upper = [fem.Function(s.function_space) for s in problem.states]
    for low, up in zip(lower, upper):
        low.x.array[:], up.x.array[:] = -1e20, 1e20
    lower[problem.names.index(name)].x.array[dofs] = -heights
    problem.set_bounds(lower, upper)
