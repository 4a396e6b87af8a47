"""Parameters of the double-chamber crater (no dolfinx here).

Lengths are in units of the crater height H, pressures in p_a (beta = mu / p_a); the
defaults are the dissertation's design (section 9.3): r0 = 0.52 H, R0 = 0.5 H, s = 0.03 H,
mu = p_a.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from bcfem.geometry.double_crater import CRATER_RADIUS, GAP, PROTUBERANCE_RADIUS, DoubleCraterGeometry
from bcfem.params import require

#: the bottom face's contact with the plate
PLATES = ("frictionless", "sticking")


@dataclass(frozen=True)
class Params:
    """The specimen, its material and the load path's controls.

    Attributes:
        crater_radius: r0 / H.
        protuberance_radius: R0 / H (< r0 / H).
        gap: s / H, the protuberance's lowest point above the plate, in (0, 1).
        beta: mu / p_a.
        kappa_ratio: bulk over shear modulus, in [10, 1e8].
        size_wall, size_contact: element sizes on the walls and where the sidewall meets the
            protuberance (and at the rims), over H.
        surface_energy: gamma / (mu r0) of the walls, in [0, 0.1].
        self_contact: the walls' self-contact penalty over mu / L, 0 or in [10, 1e4].
        plate: the specimen's bottom face on the plate: 'frictionless' (it slides) or
            'sticking' (no slip); the crater's walls on the plate slide either way.
        strain_step, max_snaps, waves: the load path's controls, as for ``crater``.
    """

    crater_radius: float = CRATER_RADIUS
    protuberance_radius: float = PROTUBERANCE_RADIUS
    gap: float = GAP
    beta: float = 1.0
    kappa_ratio: float = 1e4
    size_wall: float = 0.02
    size_contact: float = 0.005
    surface_energy: float = 0.0
    self_contact: float = 100.0
    plate: str = "frictionless"
    strain_step: float = 0.01
    max_snaps: int = 24
    waves: int = 0

    #: no lining (the crater model's reinforcement layer)
    layer_thickness: ClassVar[float] = 0.0
    layer_stiffness: ClassVar[float] = 1.0

    def __post_init__(self):
        require(self.beta > 0 and math.isfinite(self.beta), f"beta must be > 0 (got {self.beta})")
        require(10 <= self.kappa_ratio <= 1e8, f"kappa-ratio must be in [10, 1e8] (got {self.kappa_ratio})")
        require(0 <= self.surface_energy <= 0.1, f"surface-energy must be in [0, 0.1] (got {self.surface_energy})")
        require(self.self_contact == 0 or 10 <= self.self_contact <= 1e4,
                f"self-contact must be 0 (off) or in [10, 1e4] (got {self.self_contact})")
        require(self.plate in PLATES, f"plate must be one of {list(PLATES)} (got {self.plate!r})")
        require(0 < self.strain_step <= 0.1, f"strain-step must be in (0, 0.1] (got {self.strain_step})")
        self.geometry()  # a protuberance that does not fit, s <= 0, R0 >= r0: ValueError naming it

    def geometry(self) -> DoubleCraterGeometry:
        return DoubleCraterGeometry(crater_height=1.0, crater_radius=self.crater_radius,
                                    protuberance_radius=self.protuberance_radius, gap=self.gap,
                                    size_wall=self.size_wall, size_contact=self.size_contact,
                                    size_corner=self.size_contact, size_far=max(0.25, self.size_wall))

    @property
    def specimen_height(self) -> float:
        return self.geometry().specimen_height
