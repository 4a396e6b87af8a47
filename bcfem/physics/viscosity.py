r"""The viscous (proximal) term of pseudo-time relaxation (:mod:`bcfem.path.relaxation`).

.. math:: \frac{c}{2} \int |u - u_{prev}|^2 \, dV

It vanishes at rest and is off (c = 0) in every final Newton solve, so it selects which
stable state a relaxation falls into, never the state.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import ufl
from dolfinx import fem

from bcfem.mpi import global_sum
from bcfem.physics.protocols import Term

if TYPE_CHECKING:
    from bcfem.physics.context import Context


class Viscosity(Term):
    """The proximal term ``(c/2) ∫ |u - u_prev|² dV``; c = 0 (off) unless relaxing.

    The viscosity c is the run-time constant ``viscosity``; no states are added."""

    name = "viscosity"
    multipliers = ()

    def __init__(self, u: fem.Function):
        self.previous = fem.Function(u.function_space, name="previous_displacement")
        self._increments: dict[int, fem.Form] = {}

    def energy(self, ctx: Context) -> ufl.Form:
        d = ctx.u - self.previous
        return 0.5 * ctx.constant("viscosity", 0.0) * ctx.kin.integral(ufl.inner(d, d))

    def increment(self, ctx: Context) -> float:
        """‖u - u_prev‖ over the body (L2 with the volume weight); collective, its form
        compiled on the first call for ``ctx``."""
        if id(ctx) not in self._increments:
            d = ctx.u - self.previous
            self._increments[id(ctx)] = fem.form(ctx.kin.integral(ufl.inner(d, d)))
        return math.sqrt(max(global_sum(self._increments[id(ctx)]), 0.0))
