r"""The adhesive edge on a soft substrate: the debond radius R1 as a state on a fixed mesh.

The mesh keeps its contact vertex at :math:`\xi = 1` (the refinement stays there); the
material points follow from a map of the mesh coordinate,

.. math:: X(\xi, Z) = \bigl(\xi + (R_1 - 1)\,\psi(\xi, Z),\; Z\bigr),

with :math:`\psi` = 1 on a plateau around the contact vertex, falling linearly to 0 at the
axis, the far side and a depth below the top (a P1 field, so the map is exact per cell).
Membrane and substrate share their material points, so the membrane's point R1 sits on the
substrate's at the vertex for every R1. Positions are :math:`\xi + u` and do not depend on
R1: the volume and the current areas do not see it, the strain energies do. Around the
vertex the map is a translation, so the singular field of the contact line's line force is
carried along unchanged; :math:`\partial\Pi/\partial R_1` at equilibrium is then a domain
integral of the Eshelby stress over the ramps of :math:`\psi` (the J-integral of the
moving front), and ``ufl.derivative`` gives it with its exact linearisation.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem

from bcfem.scenes.blister_soft.params import FRONT_PLATEAU as PLATEAU

#: depth below the plateau over which psi falls to 0, in R0
DEPTH = 1.0


def weight_function(size_factor: float):
    """psi(x) on the substrate block [0, L] x [-L, 0], for ``interpolate``."""
    L, a = size_factor, PLATEAU

    def psi(x):
        radial = np.minimum(x[0] / (1 - a), (L - x[0]) / (L - 1 - a))
        vertical = (x[1] + a + DEPTH) / DEPTH
        return np.clip(radial, 0, 1) * np.clip(vertical, 0, 1)

    return psi


def front_weight(mesh, size_factor: float) -> fem.Function:
    """psi as a P1 field."""
    weight = fem.Function(fem.functionspace(mesh, ("Lagrange", 1)), name="front_weight")
    weight.interpolate(weight_function(size_factor))
    return weight


def material_coordinates(mesh, debond_radius, weight):
    """X(xi, Z) for the debond radius state R1 (a UFL vector)."""
    x = ufl.SpatialCoordinate(mesh)
    return ufl.as_vector([x[0] + (debond_radius - 1) * weight, x[1]])

