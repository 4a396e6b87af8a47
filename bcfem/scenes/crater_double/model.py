"""The crater model on the double-chamber geometry: the same terms, contact with the plate
and self-contact, on a wall of three tagged parts (sidewall, roof, protuberance), so that
the sidewall's contact with the protuberance is the wall's self-contact."""

from __future__ import annotations

import numpy as np

from bcfem.bcs import component
from bcfem.geometry.double_crater import BOTTOM, WALLS, create_mesh
from bcfem.scenes.crater.model import Crater

#: a wall node lies on a reference surface to this fraction of H (P2 nodes lie on it exactly)
ON_SURFACE = 1e-6


class DoubleCrater(Crater):
    """:class:`~bcfem.scenes.crater.model.Crater` on :mod:`bcfem.geometry.double_crater`
    (parameters: :class:`bcfem.scenes.crater_double.params.Params`)."""

    walls = WALLS
    create_mesh = staticmethod(create_mesh)

    def _bcs(self, V, facets):
        """The crater's, and no slip of the bottom face with ``plate='sticking'``."""
        bcs = super()._bcs(V, facets)
        if self.params.plate == "sticking":
            bcs.append(component(V, 0, facets.find(BOTTOM)))
        return bcs

    def sidewall_contact(self) -> tuple[float, float] | None:
        """The reference heights (Z_w, Z_b) of the sidewall's and the protuberance's points in
        the deepest contact between the two (a node of one behind a segment of the other), or
        None: until then the cavity is one chamber. Contacts of the roof with the
        protuberance, where the roof folds onto it at the neck, do not split it (collective)."""
        contact = self.self_contact
        if contact is None:
            raise ValueError("the chambers split by self-contact: self-contact must be on")
        nodes, segments, gaps = contact.contacts()
        X, ends = contact.X, contact.segments[segments]
        side_node, side_segment = self._on_sidewall(X[nodes]), self._on_sidewall(X[ends[:, 0]]) & self._on_sidewall(
            X[ends[:, 1]])
        ball_node = self._on_protuberance(X[nodes])
        ball_segment = self._on_protuberance(X[ends[:, 0]]) & self._on_protuberance(X[ends[:, 1]])
        splits = (side_node & ball_segment) | (ball_node & side_segment)
        heights = 0.5 * (X[ends[:, 0], 1] + X[ends[:, 1], 1])  # the segment's reference height
        candidates = [(float(g), float(np.where(s, z_node, z_seg)), float(np.where(s, z_seg, z_node)))
                      for g, s, z_node, z_seg in zip(gaps[splits], side_node[splits], X[nodes][splits, 1],
                                                     heights[splits])]
        everyone = [c for part in self.mesh.comm.allgather(candidates) for c in part]
        if not everyone:
            return None
        _, Zw, Zb = min(everyone)
        return Zw, Zb

    def _on_sidewall(self, points: np.ndarray) -> np.ndarray:
        g = self.geometry
        tol = ON_SURFACE * g.crater_height
        return (np.abs(points[:, 0] - g.r0) < tol) & (points[:, 1] > tol) & (points[:, 1] < g.crater_height - tol)

    def _on_protuberance(self, points: np.ndarray) -> np.ndarray:
        g = self.geometry
        distance = np.hypot(points[:, 0], points[:, 1] - g.centre_height)
        return (np.abs(distance - g.R0) < ON_SURFACE * g.crater_height) & (points[:, 1] < g.crater_height - 1e-12)
