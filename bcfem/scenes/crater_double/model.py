r"""The crater model on the double-chamber geometry: the same terms, contact with the plate
and self-contact, on a wall of three tagged parts (sidewall, roof, protuberance), so that
the sidewall's contact with the protuberance is the wall's self-contact.

Its chambers (:mod:`bcfem.scenes.crater_double.chambers`) are split where the sidewall first touches the
protuberance. The fluid force on the specimen is that of the chamber on the plate: the
pressure difference times the plate's wetted annulus, between the protuberance's footprint
and the sidewall's edge (the chamber under the roof is enclosed by the specimen alone).

With ``bottom = contact`` the bottom face out to the seal's reach bounds the cavity and C1 (it
is tagged :data:`SEALED_BOTTOM`, not the single crater's tag, which is the sidewall's here), and
the wetted area is dV/d(lift of the whole specimen), the annulus between the protuberance's
footprint and the sealed contact line: C2 is enclosed by the specimen, so its volume does not
change with a lift, and dV/d(lift) = dV_C1/d(lift).

The Lagrangian is the crater's (:mod:`bcfem.scenes.crater.model`) with one fluid term per
chamber:

.. math:: L = \int_\Omega W(F, p_s)\,dV + \gamma\int_{\Gamma_w} da
          + \sum_{i} \Pi_f(V_{C_i}(u), p_i) + \Pi_c(u),

one chamber (the whole cavity) until the sidewall touches the protuberance, C1 and C2 after."""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem, mesh

from bcfem.contact.self_contact import WallSelfContact
from bcfem.geometry.double_crater import (
    BOTTOM,
    OUTER,
    PROTUBERANCE,
    ROOF,
    SIDEWALL,
    TOP,
    WALLS,
    DoubleCraterGeometry,
    create_mesh,
)
from bcfem.mpi import global_sum, real_value
from bcfem.physics.bcs import component
from bcfem.physics.cavity import Cavity
from bcfem.scenes.crater.model import CONTACT_GAP, SEAL_REACH, Crater
from bcfem.scenes.crater.model import SEALED_BOTTOM as CRATER_SEALED_BOTTOM
from bcfem.scenes.crater_double.chambers import ChamberSplit
from bcfem.scenes.crater_double.params import DoubleSpecimen

#: a wall node lies on a reference surface to this fraction of H (P2 nodes lie on it exactly)
ON_SURFACE = 1e-6
#: the facet tag of the bottom face inside the seal's reach (``bottom = contact``)
SEALED_BOTTOM = 19


class DoubleCrater(Crater):
    """:class:`~bcfem.scenes.crater.model.Crater` on :mod:`bcfem.geometry.double_crater`
    (built from :class:`bcfem.scenes.crater_double.params.DoubleSpecimen`)."""

    walls = WALLS
    create_mesh = staticmethod(create_mesh)

    params: DoubleSpecimen
    geometry: DoubleCraterGeometry

    def __init__(self, params: DoubleSpecimen, comm):
        super().__init__(params, comm)
        gap = CONTACT_GAP * self.geometry.r0 if self.bottom_contact else 0.0
        if self.bottom_contact:  # the crater's cavity and wetted area, on this geometry's tag
            self.cavity = Cavity((*self.walls, SEALED_BOTTOM), gap)
            self.volume = fem.form(self.cavity.volume(self.ctx.kin))
            lift = fem.Function(self.u.function_space)
            lift.interpolate(lambda x: np.vstack([0 * x[0], 1 + 0 * x[0]]))
            self._wetted = fem.form(ufl.derivative(self.cavity.volume(self.ctx.kin), self.u, lift))
            del self.__dict__["wetted_area"]  # the crater's form; here a method
        # without a protuberance the cavity never splits
        sealed = SEALED_BOTTOM if self.bottom_contact else None
        self.split = (ChamberSplit(self.mesh, self.facet_tags, SIDEWALL, ROOF, PROTUBERANCE, sealed=sealed,
                                   contact_gap=gap)
                      if self.geometry.has_protuberance else None)
        self.chambers = self.split.chambers() if self.split else []
        self.chamber_volumes = [fem.form(c.volume(self.ctx.kin)) for c in self.chambers]
        X = self._wall[0]
        self._sidewall_nodes = self._on_sidewall(X) | (np.hypot(X[:, 0] - self.geometry.r0, X[:, 1])
                                                       < ON_SURFACE * self.geometry.crater_height)
        self._protuberance_nodes = self._on_protuberance(X)

    @property
    def chamber_split(self) -> ChamberSplit:
        """The chambers' split (a geometry with a protuberance)."""
        if self.split is None:
            raise RuntimeError("a crater without a protuberance has one chamber")
        return self.split

    @property
    def wall_contact(self) -> WallSelfContact:
        """The walls' self-contact (which this scene's chambers need)."""
        if self.self_contact is None:
            raise RuntimeError("the double crater's chambers need --self-contact > 0")
        return self.self_contact

    def _tag_sealed_bottom(self, msh, facets):
        """The crater's retagging, to :data:`SEALED_BOTTOM` (the crater's tag is the sidewall's)."""
        crater = super()._tag_sealed_bottom(msh, facets)
        values = crater.values.copy()
        values[(facets.values == BOTTOM) & (crater.values == CRATER_SEALED_BOTTOM)] = SEALED_BOTTOM
        return mesh.meshtags(msh, 1, facets.indices, values)

    @property
    def spreads(self) -> bool:
        """Whether the cell of an array spreads: its outer face is a mirror plane of the lattice, so
        it moves as a whole, and it can only where neither the plate nor the platen holds the
        faces' radii (else the rollers are exact)."""
        p = self.params
        return p.cell == "array" and p.plate == "frictionless" and p.top == "sliding"

    def _lift(self, V, comm):
        """The crater's, plus, for a cell that spreads, e g(r) e_r: the outer face r = R moves
        to R (1 + e) with the lateral strain e (a real state; its residual, the derivative of
        the energy, is the mean lateral traction on the face: zero). g rises linearly from 0 at
        the walls (or at the seal's reach, ``bottom = contact``) to R at the face, so the
        walls' unknowns, contact bounds and self-contact see no lift; any such g spans the
        same discrete solutions as e r, since g is interpolated in the displacement's space."""
        lift = super()._lift(V, comm)
        #: the lateral strain as an unknown, else None
        self.lateral_state = None
        if not self.spreads:
            return lift
        r0, R = self.geometry.r0, self.geometry.specimen_radius
        inner = r0 + (SEAL_REACH * (R - r0) if self.bottom_contact else 0.0)
        shape = fem.Function(V.sub(0).collapse()[0], name="lateral_shape")
        shape.interpolate(lambda x: R * np.clip((x[0] - inner) / (R - inner), 0.0, 1.0))
        self.lateral_state = self.ctx.real_state("lateral_strain")
        lateral = ufl.as_vector([self.lateral_state * shape, 0])
        return lateral if lift is None else lift + lateral

    def lateral_strain(self) -> float | None:
        """The cell's lateral strain (0 on rollers), None for an isolated specimen."""
        if self.params.cell == "isolated":
            return None
        return real_value(self.lateral_state) if self.lateral_state is not None else 0.0

    def _bcs(self, V, facets):
        """The crater's; no slip of the bottom face with ``plate='sticking'`` (with ``bottom =
        contact`` also where it lifts), of the top face with ``top='bonded'``; for the cell of
        an array, u_r held on the outer face beyond the lateral lift (rollers where it does not
        spread, or with ``cell='array-confined'``)."""
        bcs = super()._bcs(V, facets)
        if self.params.plate == "sticking":
            bcs.append(component(V, 0, np.concatenate([facets.find(BOTTOM), facets.find(SEALED_BOTTOM)])))
        if self.params.top == "bonded":
            bcs.append(component(V, 0, facets.find(TOP)))
        if self.params.cell != "isolated":
            bcs.append(component(V, 0, facets.find(OUTER)))
        return bcs

    def split_at(self, heights: tuple[float, float]) -> tuple[float, float]:
        """Split the chambers at the reference heights (Z_w, Z_b) (snapped to wall vertices);
        returns their current volumes (V_C1, V_C2)."""
        self.chamber_split.move(*heights)
        return self.chamber_volumes_now()

    def chamber_volumes_now(self) -> tuple[float, float]:
        return global_sum(self.chamber_volumes[0]), global_sum(self.chamber_volumes[1])

    def open_radius(self) -> float:
        """Where the sidewall leaves the plate (the rim, or above it once it rolls onto the plate)."""
        return self.plate_edge(self._sidewall_nodes)

    def footprint_radius(self) -> float:
        """The radius of the protuberance's contact patch on the plate (0: off the plate)."""
        return self.plate_edge(self._protuberance_nodes)

    def wetted_area(self) -> float:
        """The plate's area wetted by the chamber on it: pi (r_edge^2 - r_footprint^2); with the
        bottom face in contact, dV/d(lift), r_edge the sealed contact line."""
        if self.bottom_contact:
            return global_sum(self._wetted)
        return math.pi * (self.open_radius() ** 2 - self.footprint_radius() ** 2)

    def sidewall_contact(self) -> tuple[float, float] | None:
        """The reference heights (Z_w, Z_b) of the sidewall's and the protuberance's points in
        the deepest contact between the two (a node of one behind a segment of the other), or
        None: until then the cavity is one chamber. Contacts of the roof with the
        protuberance, where the roof folds onto it at the neck, do not split it (collective)."""
        X = self.wall_contact.X
        nodes, segments, gaps, side_node = self._split_contacts()
        heights = X[self.wall_contact.segments[segments]][:, :, 1].mean(axis=1)  # a segment's reference height
        candidates = [(float(g), float(z_node) if s else float(z_seg), float(z_seg) if s else float(z_node))
                      for g, s, z_node, z_seg in zip(gaps, side_node, X[nodes, 1], heights)]
        everyone = [c for part in self.mesh.comm.allgather(candidates) for c in part]
        if not everyone:
            return None
        _, Zw, Zb = min(everyone)
        return Zw, Zb

    def bond_split(self) -> int:
        """Hold the sidewall-protuberance contacts of this state together from now on (the
        dissertation's non-separable contact); returns how many pairs (collective)."""
        nodes, segments, _, _ = self._split_contacts()
        self.wall_contact.bond(nodes, segments)
        return self.mesh.comm.allreduce(len(nodes))

    def sidewall_gap(self) -> float | None:
        """The least distance from a sidewall node to the protuberance's polyline (collective):
        how far the cavity is from splitting (negative values are not reported: in contact the
        penalty's penetration is O(L / c_k)); None without a protuberance."""
        if not self.geometry.has_protuberance:
            return None
        contact = self.wall_contact
        x, X, segments = contact._positions(), contact.X, contact.segments
        side = x[self._on_sidewall(X)]
        ends = segments[self._on_protuberance(X[segments[:, 0]]) & self._on_protuberance(X[segments[:, 1]])]
        a, d = x[ends[:, 0]], x[ends[:, 1]] - x[ends[:, 0]]
        v = side[:, None, :] - a[None, :, :]
        t = np.clip(np.einsum("ijk,jk->ij", v, d) / np.einsum("jk,jk->j", d, d), 0.0, 1.0)
        return float(np.linalg.norm(v - t[..., None] * d[None], axis=2).min(initial=np.inf))

    def _split_contacts(self):
        """This rank's contacts of a sidewall node with a protuberance segment or the reverse:
        (nodes, segments, gaps, node on the sidewall)."""
        contact = self.wall_contact
        if contact is None:
            raise ValueError("the chambers split by self-contact: self-contact must be on")
        nodes, segments, gaps = contact.contacts()
        X, ends = contact.X, contact.segments[segments]
        side_node = self._on_sidewall(X[nodes])
        side_segment = self._on_sidewall(X[ends[:, 0]]) & self._on_sidewall(X[ends[:, 1]])
        ball_node = self._on_protuberance(X[nodes])
        ball_segment = self._on_protuberance(X[ends[:, 0]]) & self._on_protuberance(X[ends[:, 1]])
        splits = (side_node & ball_segment) | (ball_node & side_segment)
        return nodes[splits], segments[splits], gaps[splits], side_node[splits]

    def _on_sidewall(self, points: np.ndarray) -> np.ndarray:
        g = self.geometry
        tol = ON_SURFACE * g.crater_height
        return (np.abs(points[:, 0] - g.r0) < tol) & (points[:, 1] > tol) & (points[:, 1] < g.crater_height - tol)

    def _on_protuberance(self, points: np.ndarray) -> np.ndarray:
        g = self.geometry
        distance = np.hypot(points[:, 0], points[:, 1] - g.centre_height)
        return (np.abs(distance - g.R0) < ON_SURFACE * g.crater_height) & (points[:, 1] < g.crater_height - 1e-12)
