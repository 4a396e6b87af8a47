"""Hyperelastic strain-energy densities, as functions of the first invariant.

A material is only a strain energy: a frozen, validated dataclass whose
``strain_energy(I1)`` returns a UFL expression (energy per unit reference
volume). Kinematics decide what ``I1`` is (membrane or solid); the material
does not know.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import ufl


def _require(condition: bool, message: str) -> None:
    if not condition:
        raise ValueError(message)


@dataclass(frozen=True)
class NeoHookean:
    r"""Incompressible neo-Hookean solid, :math:`W = \tfrac{\mu}{2}(I_1 - 3)` (eq. 3.37).

    Attributes:
        mu: small-strain shear modulus [Pa]; 1 in normalised units.
    """

    mu: float = 1.0  # [Pa]
    name = "neo-hookean"

    def __post_init__(self):
        _require(math.isfinite(self.mu) and self.mu > 0, f"mu must be > 0 (got {self.mu})")

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
        _require(math.isfinite(self.mu) and self.mu > 0, f"mu must be > 0 (got {self.mu})")
        _require(self.Jm > 0 and not math.isnan(self.Jm), f"Jm must be > 0 (got {self.Jm}); use inf for neo-Hookean")

    def strain_energy(self, I1):
        if math.isinf(self.Jm):
            return 0.5 * self.mu * (I1 - 3)
        return -0.5 * self.mu * self.Jm * ufl.ln(1 - (I1 - 3) / self.Jm)


MATERIALS = {"neo-hookean": NeoHookean, "gent": Gent}
