r"""A cavity closed by the rigid plate z = 0: its current volume.

The crater's current volume follows from its surface alone (divergence
theorem with the field z e_z, which vanishes on the plate), mapped to the
reference surface by Nanson's formula, n da = cof(F) N dA:

.. math:: V(u) = -\int_\Gamma z\,(\mathrm{cof}(F) N)_z\, dA,

with N the reference normal pointing out of the solid (into the cavity). The
kinematics supply z, cof(F) N and the surface measure, so the same functional
serves an axisymmetric state and its Fourier modes (:mod:`bcfem.stability.modes`).
"""

from __future__ import annotations

from dataclasses import dataclass

import ufl


@dataclass(frozen=True)
class Cavity:
    """The cavity bounded by the boundary part ``boundary`` and the plate z = 0.

    With ``contact_gap`` g > 0 the height z enters as z^2 / sqrt(z^2 + g^2): that and its slope
    vanish where the boundary lies on the plate, so a part on the plate is not wetted (its
    lift would open a gap there, not change the cavity), and it is z to O(g^2/z) where the
    boundary has lifted. A face that lies on the plate at rest (a bottom face that may lift
    off into the cavity) can then be part of ``boundary``.

    Attributes:
        boundary: facet tag (or tuple of tags) of the cavity's wall.
        contact_gap: g, a length far below the lifts that matter (0: z as it is).
    """

    boundary: int | tuple[int, ...]
    contact_gap: float = 0.0

    def height(self, kin):
        """The height z the volume integrates: z itself, or z^2 / sqrt(z^2 + g^2) with a gap g."""
        z = kin.height
        if self.contact_gap > 0:
            z = z * z / ufl.sqrt(z * z + self.contact_gap**2)
        return z

    def volume(self, kin):
        """The current volume as a form over the wall (kinematics with ``height``,
        ``vertical_area()`` and ``surface_integral``)."""
        return kin.surface_integral(-self.height(kin) * kin.vertical_area(), self.boundary)
