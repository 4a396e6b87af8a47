r"""The two chambers of a double-chamber crater, split at material points of its walls.

Once the sidewall touches the protuberance (:mod:`bcfem.geometry.double_crater`)
the cavity is two chambers: C1 on the plate and C2 under the roof. Their
walls are the cavity's walls cut at one material point on the sidewall and one
on the protuberance (the contact point's reference positions, of reference
heights Z_w and Z_b). As for the whole cavity (:class:`bcfem.physics.cavity.Cavity`),
each volume follows from its walls by the divergence theorem with z e_z (a bottom face that
may lift off the plate, ``sealed``, bounds C1 as it bounds the cavity):

.. math:: V_{C1}(u) = -\int_{\Gamma_w, Z < Z_w} z\,(\mathrm{cof}F\,N)_z\,dA
                      -\int_{\Gamma_b, Z < Z_b} z\,(\mathrm{cof}F\,N)_z\,dA + P,
          \qquad V_{C2}(u) = V(u) - V_{C1}(u),

with N the reference normal out of the solid (into the cavity); the roof
belongs to C2. P is the flux of z e_z through the plug, the conical surface
between the two split points' current circles (normal towards C2): it
vanishes once the gap is closed (the two points' radii agree), and the forms
leave it out; :func:`plug_flux` gives it in closed form for an open gap.

The split heights are ``fem.Constant``\ s, so the forms compile once and the
split moves without recompilation. The indicator of Z < Z_split is exact only
if no facet straddles the split: :meth:`ChamberSplit.move` puts each split at
a mesh vertex of its wall (the walls' meridians are monotone in Z, so a
height names one material point).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import default_scalar_type, fem
from dolfinx.mesh import entities_to_geometry

from bcfem.physics.cavity import Cavity


def plug_flux(protuberance_point, sidewall_point) -> float:
    r"""The flux of z e_z through the plug between the split points' circles, towards C2.

    The plug is the surface of revolution of the segment from the protuberance's
    point (r_b, z_b) to the sidewall's point (r_w, z_w):
    :math:`P = 2\pi\int r z\,dr = 2\pi\Delta r\,(r_b z_b + (z_b\Delta r + r_b\Delta z)/2 + \Delta r\Delta z/3)`.
    It is zero when Δr = 0: a closed gap, or a cylindrical plug.
    """
    (rb, zb), (rw, zw) = protuberance_point, sidewall_point
    dr, dz = rw - rb, zw - zb
    return 2 * math.pi * dr * (rb * zb + 0.5 * (zb * dr + rb * dz) + dr * dz / 3)


def wall_vertex_heights(mesh, facet_tags, tag: int) -> np.ndarray:
    """The sorted reference heights Z of the mesh vertices on the boundary part ``tag``, on every rank."""
    fdim = mesh.topology.dim - 1
    mesh.topology.create_connectivity(fdim, mesh.topology.dim)
    # a facet's first two geometry nodes are its vertices (then its midpoint, if curved)
    nodes = entities_to_geometry(mesh, fdim, facet_tags.find(tag))[:, :2]
    heights = mesh.geometry.x[nodes.ravel(), 1]
    return np.unique(np.concatenate(mesh.comm.allgather(heights)))


class ChamberSplit:
    """Where the walls of a double-chamber crater divide C1 from C2: two reference heights as constants.

    Args:
        mesh: the reference mesh.
        facet_tags: its boundary markers.
        sidewall, roof, protuberance: the tags of the cavity's walls.
        sidewall_height, protuberance_height: the initial split heights Z_w and
            Z_b (snapped to vertices).
        sealed: the tag of a bottom face that may lift off the plate (it bounds C1), or None.
        contact_gap: the cavity's gap g (:class:`bcfem.physics.cavity.Cavity`): with a sealed bottom,
            the walls' height enters as z^2 / sqrt(z^2 + g^2), so that V_C1 + V_C2 = V.
    """

    def __init__(self, mesh, facet_tags, sidewall: int, roof: int, protuberance: int,
                 sidewall_height: float = 0.0, protuberance_height: float = 0.0,
                 sealed: int | None = None, contact_gap: float = 0.0):
        self.mesh = mesh
        self.sidewall, self.roof, self.protuberance = sidewall, roof, protuberance
        self.sealed, self.height = sealed, Cavity(sidewall, contact_gap).height
        self._heights = {sidewall: wall_vertex_heights(mesh, facet_tags, sidewall),
                         protuberance: wall_vertex_heights(mesh, facet_tags, protuberance)}
        #: Z_w, the reference height of the split on the sidewall
        self.sidewall_height = fem.Constant(mesh, default_scalar_type(0.0))
        #: Z_b, the reference height of the split on the protuberance
        self.protuberance_height = fem.Constant(mesh, default_scalar_type(0.0))
        self.move(sidewall_height, protuberance_height)

    def snap(self, tag: int, height: float) -> float:
        """The height of the vertex of wall ``tag`` nearest to ``height``."""
        heights = self._heights[tag]
        return float(heights[np.abs(heights - height).argmin()])

    def move(self, sidewall_height: float, protuberance_height: float) -> tuple[float, float]:
        """Split at the vertices nearest the given reference heights; returns (Z_w, Z_b) as set."""
        self.sidewall_height.value = np.asarray(self.snap(self.sidewall, sidewall_height))
        self.protuberance_height.value = np.asarray(self.snap(self.protuberance, protuberance_height))
        return float(self.sidewall_height.value), float(self.protuberance_height.value)

    def chambers(self) -> tuple[Chamber, Chamber]:
        """(C1, C2): the chamber on the plate and the one under the roof."""
        return Chamber(self, lower=True), Chamber(self, lower=False)


@dataclass(frozen=True)
class Chamber:
    """One chamber of a split double-chamber crater: a cavity for :mod:`bcfem.physics.fluids`.

    Attributes:
        split: the split of the walls.
        lower: True for C1 (on the plate: the walls below the split), False for
            C2 (the rest, with the roof).
    """

    split: ChamberSplit
    lower: bool

    def volume(self, kin):
        """The chamber's current volume without the plug, as a form over its walls (kinematics
        with ``height``, ``vertical_area()`` and ``surface_integral``)."""
        s = self.split
        Z = ufl.SpatialCoordinate(s.mesh)[1]
        flux = -s.height(kin) * kin.vertical_area()

        def below(height):
            inside = ufl.conditional(ufl.lt(Z, height), 1.0, 0.0)
            return inside if self.lower else 1.0 - inside

        form = (kin.surface_integral(below(s.sidewall_height) * flux, s.sidewall)
                + kin.surface_integral(below(s.protuberance_height) * flux, s.protuberance))
        if not self.lower:
            return form + kin.surface_integral(flux, s.roof)
        return form if s.sealed is None else form + kin.surface_integral(flux, s.sealed)
