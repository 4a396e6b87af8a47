r"""Fluids sealed in a cavity, as energy terms in the cavity's current volume V(u).

Pressures are in units of the ambient pressure p_a, which acts outside. Each
sealed fluid adds its pressure p as a global unknown (a real-space state,
``pressure_name``); its row is the fluid's equation of state:

* :class:`IdealGas`: :math:`-(p-1)V + V_1\ln p`; stationary in p: Boyle's law
  :math:`pV = V_1` (isothermal, sealed at p = 1 and volume V1);
* :class:`IncompressibleLiquid`: :math:`-(p-1)(V - V_1)`; stationary in p: V = V1;
* :class:`HeldPressure`: :math:`-(p_h-1)V`: a cavity at a given pressure p_h (a liquid's
  vapour once it has cavitated);
* :class:`Vacuum`: :math:`sV`: an empty cavity, the ambient pressure alone
  (s ramps the suction on when a closed cavity is sealed).

In every case the derivative in u is the pressure difference (p - 1) times
the variation of V, a follower load linearised exactly by UFL. Constants that
are not integrals over the body (V1 ln p, (p-1)V1) are spread over the body's
measure so that each term is one form.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import ufl

from bcfem.physics.protocols import Term

if TYPE_CHECKING:
    from bcfem.physics.context import Context
    from bcfem.physics.protocols import Enclosure


def over_body(ctx: Context, value) -> ufl.Form:
    """``value`` as an integrand over the body: value / |body| dx (:meth:`Context.body_measure`)."""
    return value / ctx.body_measure() * ufl.dx(domain=ctx.mesh)


@dataclass(frozen=True)
class SealedFluid(Term):
    """A fluid sealed at p = 1 in volume ``sealed_volume``.

    Its pressure is a multiplier (:class:`bcfem.physics.protocols.Term`): the row in p is
    the equation of state, and the p-p block of the tangent is negative
    (-V1/p^2 for a gas) or zero (a liquid), one negative eigenvalue either way.

    Attributes:
        cavity: the cavity (:class:`bcfem.physics.cavity.Cavity`): its current volume V(u).
        sealed_volume: V1, the volume at sealing (> 0).
        pressure_name: name of the pressure state.
    """

    cavity: Enclosure
    sealed_volume: float
    pressure_name: str = "fluid_pressure"
    name = "sealed_fluid"

    @property
    def multipliers(self) -> tuple[str, ...]:
        return (self.pressure_name,)

    def unknowns(self, ctx):
        """(pressure state, the sealed amount: this fluid's constant, named
        ``<pressure_name>_sealed`` for :meth:`Context.set`, so that several chambers, sealed
        apart, live in one model)."""
        amount = ctx.parameters(self, {"sealed_volume": f"{self.pressure_name}_sealed"}).sealed_volume
        return ctx.real_state(self.pressure_name), amount


class IdealGas(SealedFluid):
    """p V = V1 (isothermal)."""

    name = "ideal_gas"

    def energy(self, ctx: Context) -> ufl.Form:
        p, amount = self.unknowns(ctx)
        return -(p - 1.0) * self.cavity.volume(ctx.kin) + over_body(ctx, amount * ufl.ln(p))


class IncompressibleLiquid(SealedFluid):
    """V = V1, p its multiplier (p may turn negative; a scene that models cavitation
    replaces the term by :class:`HeldPressure` where p falls to the vapour pressure)."""

    name = "incompressible_liquid"

    def energy(self, ctx: Context) -> ufl.Form:
        p, amount = self.unknowns(ctx)
        # a zero (p - 1)^2 term puts the pressure's diagonal into the sparsity pattern,
        # which PETSc's VI reduction and zeroRowsColumns need
        zero = ctx.constant("liquid_pressure_diagonal", 0.0)
        return -(p - 1.0) * self.cavity.volume(ctx.kin) + over_body(ctx, (p - 1.0) * amount + zero * (p - 1.0) ** 2)


@dataclass(frozen=True)
class HeldPressure(Term):
    """A cavity at the pressure ``pressure`` (over p_a) whatever its volume: a liquid that has
    cavitated, its vapour at the vapour pressure. No unknown: the volume is free."""

    cavity: Enclosure
    pressure: float
    pressure_name: str = "fluid_pressure"
    multipliers = ()

    @property
    def name(self) -> str:
        return f"{self.pressure_name}_held"

    def energy(self, ctx: Context) -> ufl.Form:
        p = ctx.parameters(self, {"pressure": self.name}).pressure
        return -(p - 1.0) * self.cavity.volume(ctx.kin)


@dataclass(frozen=True)
class Vacuum(Term):
    """An empty cavity: p = 0 inside, the ambient pressure's work s·V (s = ``vacuum_load``)."""

    cavity: Enclosure
    name = "vacuum"
    multipliers = ()

    def energy(self, ctx: Context) -> ufl.Form:
        return ctx.constant("vacuum_load", 0.0) * self.cavity.volume(ctx.kin)


#: fluid name -> sealed fluid term
FLUIDS = {"air": IdealGas, "liquid": IncompressibleLiquid}
