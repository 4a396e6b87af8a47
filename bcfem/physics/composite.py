r"""Terms made of terms: a term evaluated on another kinematics (:class:`OnSurface`), and a
term scaled by a run-time constant (:class:`Scaled`). Neither writes an energy of its own."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import ufl

from bcfem.physics.protocols import Term

if TYPE_CHECKING:
    from bcfem.physics.context import Context


@dataclass(frozen=True)
class OnSurface(Term):
    r"""The energy of a membrane term evaluated on a surface: ``term.energy`` with ``ctx.kin``
    replaced by ``surface`` (a :class:`MembraneSurface` or :class:`LiquidGap`).

    E.g. ``OnSurface(SurfaceTension(0.5, "gamma_ls"), wetted)`` is
    :math:`\gamma_{ls} A_{ls} = \gamma_{ls}\int \lambda_r^s\lambda_\theta^s\,dA` of the
    deformed wetted substrate, and ``OnSurface(MembraneStrain(NeoHookean()), bonded)`` the
    strain energy of the membrane bonded to the substrate (a surface hyperelastic term).
    The term's states and run-time constants are the context's own.

    Attributes:
        term: a term that reads only the members of :class:`MembraneSurface`.
        surface: the kinematics it is evaluated with.
        label: names the surface in the term's ``name``.
    """

    term: Term
    surface: object = field(compare=False)
    label: str = "surface"

    @property
    def name(self) -> str:
        return f"{self.term.name}@{self.label}"

    @property
    def multipliers(self) -> tuple[str, ...]:
        return tuple(self.term.multipliers)

    def energy(self, ctx: Context) -> ufl.Form:
        return self.term.energy(ctx.with_kinematics(self.surface))


@dataclass(frozen=True)
class Scaled(Term):
    r"""A term's energy times a run-time constant, :math:`k\,\Pi_{term}` (e.g. a substrate's
    modulus :math:`k = \mu_s R_0/(\mu_f t_0)`, lowered during a run from a stiff start).

    Attributes:
        term: any term with one form as its energy.
        constant: the name of the run-time constant k.
        value: its value on creation, > 0.
    """

    term: Term
    constant: str
    value: float

    @property
    def name(self) -> str:
        return f"{self.constant}*{self.term.name}"

    @property
    def multipliers(self) -> tuple[str, ...]:
        return tuple(self.term.multipliers)

    def energy(self, ctx: Context) -> ufl.Form:
        k = ctx.parameters(self, {"value": self.constant}).value
        form = self.term.energy(ctx)
        return ufl.Form([i.reconstruct(integrand=k * i.integrand()) for i in form.integrals()])

    def inadmissible(self, ctx: Context) -> str | None:
        return self.term.inadmissible(ctx)
