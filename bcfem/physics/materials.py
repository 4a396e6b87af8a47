"""Hyperelastic strain-energy densities, as functions of the first invariant.

A material is only a strain energy: a frozen, validated dataclass whose
``strain_energy(I1)`` returns a UFL expression (energy per unit reference
volume). Kinematics decide what ``I1`` is (membrane or solid); the material
does not know. The term that holds a material evaluates it on
``ctx.parameters(material)``, whose moduli are ``fem.Constant`` s, so that a new
modulus compiles no form; an infinite ``Jm`` stays a number: it selects the
neo-Hookean form.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import ufl

from bcfem.params import require


@dataclass(frozen=True)
class NeoHookean:
    r"""Incompressible neo-Hookean solid, :math:`W = \tfrac{\mu}{2}(I_1 - 3)` (eq. 3.37).

    Attributes:
        mu: small-strain shear modulus [Pa]; 1 in normalised units.
    """

    mu: float = 1.0  # [Pa]
    name = "neo-hookean"

    def __post_init__(self):
        require(math.isfinite(self.mu) and self.mu > 0, f"mu must be > 0 (got {self.mu})")

    def strain_energy(self, I1):
        return 0.5 * self.mu * (I1 - 3)


@dataclass(frozen=True)
class Gent:
    r"""Incompressible Gent solid, :math:`W = -\tfrac{\mu J_m}{2}\ln(1 - (I_1-3)/J_m)` (eq. 3.38).

    ``Jm`` is the locking limit of :math:`I_1 - 3`; ``Jm = inf`` is neo-Hookean.
    Beyond the limit the logarithm is NaN, which the solver reports as a failed
    iterate (and continuation cuts the step back), never as a converged state.

    Attributes:
        mu: small-strain shear modulus [Pa]; 1 in normalised units.
        Jm: locking limit of I1 - 3 [-], in (0, inf].
    """

    mu: float = 1.0  # [Pa]
    Jm: float = 100.0  # [-]
    name = "gent"

    def __post_init__(self):
        require(math.isfinite(self.mu) and self.mu > 0, f"mu must be > 0 (got {self.mu})")
        require(self.Jm > 0 and not math.isnan(self.Jm), f"Jm must be > 0 (got {self.Jm}); use inf for neo-Hookean")

    def strain_energy(self, I1):
        if isinstance(self.Jm, float) and math.isinf(self.Jm):
            return 0.5 * self.mu * (I1 - 3)
        return -0.5 * self.mu * self.Jm * ufl.ln(1 - (I1 - 3) / self.Jm)


MATERIALS = {"neo-hookean": NeoHookean, "gent": Gent}


def slope(material, I1):
    r""":math:`\partial W/\partial I_1` of ``material`` at ``I1``, as an expression free of UFL
    variables: a variable's label is numbered anew on each use, and an interpolation expression
    (unlike a form) keeps that number in its signature, so it would compile on every build."""
    from ufl.algorithms import apply_algebra_lowering, apply_derivatives, strip_variables

    x = ufl.variable(I1)
    lowered = apply_algebra_lowering.apply_algebra_lowering(ufl.diff(material.strain_energy(x), x))
    return strip_variables(apply_derivatives.apply_derivatives(lowered))


@dataclass(frozen=True)
class NearlyIncompressibleNeoHookean:
    r"""Neo-Hookean solid with a mixed pressure, for Taylor-Hood u-p elements:

    .. math:: W = \tfrac{\mu}{2}(I_1 - 3) - \mu \ln J + p\,(J - 1) - \frac{p^2}{2\kappa},

    stationary in p where J - 1 = p/κ (so κ → ∞ is incompressible and the
    same discretisation stays free of locking). The polynomial-plus-log form
    stays finite for every iterate with J > 0 (an isochoric J^{-2/3} split
    gives NaN at the first inverted element). Not a function of I1 alone, so
    :meth:`density` takes the kinematics and the pressure field.

    Attributes:
        mu: shear modulus [Pa].
        kappa: bulk modulus [Pa], kappa/mu in (0, 1e12].
    """

    mu: float = 1.0  # [Pa]
    kappa: float = 1e6  # [Pa]
    name = "neo-hookean-mixed"

    def __post_init__(self):
        require(math.isfinite(self.mu) and self.mu > 0, f"mu must be > 0 (got {self.mu})")
        require(0 < self.kappa / self.mu <= 1e12, f"kappa/mu must be in (0, 1e12] (got {self.kappa / self.mu:g})")

    def density(self, kin, p):
        return (0.5 * self.mu * (kin.I1 - 3) - self.mu * ufl.ln(kin.J)
                + p * (kin.J - 1) - p**2 / (2 * self.kappa))
