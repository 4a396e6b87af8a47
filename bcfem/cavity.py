r"""A cavity closed by the rigid plate z = 0: its current volume.

The crater's current volume follows from its surface alone (divergence
theorem with the field z e_z, which vanishes on the plate), mapped to the
reference surface by Nanson's formula, n da = cof(F) N dA:

.. math:: V(u) = -\int_\Gamma z\,(\mathrm{cof}(F) N)_z\, dA,

with N the reference normal pointing out of the solid (into the cavity). The
kinematics supply z, cof(F) N and the surface measure, so the same functional
serves an axisymmetric state and its Fourier modes (:mod:`bcfem.modes`).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Cavity:
    """The cavity bounded by the boundary part ``boundary`` and the plate z = 0.

    Attributes:
        boundary: facet tag (or tuple of tags) of the cavity's wall.
    """

    boundary: int | tuple[int, ...]

    def volume(self, kin):
        """The current volume as a form over the wall (kinematics with ``height``,
        ``nanson()`` and ``surface_integral``)."""
        return kin.surface_integral(-kin.height * kin.nanson()[1], self.boundary)
