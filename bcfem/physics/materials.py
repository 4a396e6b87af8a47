"""Hyperelastic strain-energy densities, as functions of the first two invariants.

A material is only a strain energy: a frozen, validated dataclass whose
``strain_energy(I1, I2)`` returns a UFL expression (energy per unit reference
volume) of the first two invariants (I1 only for most: I2 is then ignored).
Kinematics decide what the invariants are (membrane or solid); the material
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

    def strain_energy(self, I1, I2=None):
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

    def strain_energy(self, I1, I2=None):
        if isinstance(self.Jm, float) and math.isinf(self.Jm):
            return 0.5 * self.mu * (I1 - 3)
        return -0.5 * self.mu * self.Jm * ufl.ln(1 - (I1 - 3) / self.Jm)


@dataclass(frozen=True)
class MooneyRivlin:
    r"""Incompressible Mooney–Rivlin solid, :math:`W = C_1(I_1 - 3) + C_2(I_2 - 3)`, with the
    small-strain shear modulus :math:`\mu = 2(C_1 + C_2)`; ``C2 = 0`` is neo-Hookean.

    Attributes:
        C1: the I1 coefficient [Pa], > 0.
        C2: the I2 coefficient [Pa], >= 0.
    """

    C1: float = 0.5  # [Pa]
    C2: float = 0.0  # [Pa]
    name = "mooney-rivlin"

    def __post_init__(self):
        require(math.isfinite(self.C1) and self.C1 > 0, f"C1 must be > 0 (got {self.C1})")
        require(math.isfinite(self.C2) and self.C2 >= 0, f"C2 must be >= 0 (got {self.C2})")

    def strain_energy(self, I1, I2=None):
        if I2 is None:
            raise ValueError("Mooney-Rivlin needs the second invariant I2 of the kinematics")
        return self.C1 * (I1 - 3) + self.C2 * (I2 - 3)


MATERIALS = {"neo-hookean": NeoHookean, "gent": Gent}


def _derivative(energy, x):
    """d energy / d x (x a UFL variable), free of UFL variables: a variable's label is numbered
    anew on each use, and an interpolation expression (unlike a form) keeps that number in its
    signature, so it would compile on every build."""
    from ufl.algorithms import apply_algebra_lowering, apply_derivatives, strip_variables

    lowered = apply_algebra_lowering.apply_algebra_lowering(ufl.diff(energy, x))
    return strip_variables(apply_derivatives.apply_derivatives(lowered))


def slopes(material, I1, I2):
    r"""(:math:`\partial W/\partial I_1`, :math:`\partial W/\partial I_2`) of ``material`` at
    (I1, I2); I2 None: a material of I1 alone, and the second is 0."""
    x = ufl.variable(I1)
    if I2 is None:
        return _derivative(material.strain_energy(x), x), 0.0
    y = ufl.variable(I2)
    energy = material.strain_energy(x, y)
    return _derivative(energy, x), _derivative(energy, y)


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
