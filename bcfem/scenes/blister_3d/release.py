r"""The energy release rate along the blister's outline: where and when the adhesive edge
starts to debond (Griffith's criterion on a front that may move anywhere in the plane).

The sharp adhesive edge of ``blister-rigid`` moves its debond radius R1 where the
configurational force -∂Π/∂R1 turns positive. In the plane the front can move differently at
each point, so the same derivative is taken for every motion of the outline at once: moving
the reference points by εθ(X) (the film's displacement held as a function of the moved points,
so the outline stays on the unstretched bonded film, as the sharp edge's u(R1) = 0), the
free energy changes by

.. math:: \frac{d\Pi}{d\varepsilon} = \sum_i g_i\cdot\theta_i
   = -\oint (\mathcal{G} - w - \alpha)\,\theta\cdot\nu\, ds

at equilibrium, with :math:`\mathcal{G}` the release rate and w + α the cost of debonding a flat
unit area (the ``WettedSubstrate`` and ``SurfaceTension`` terms' share of Π). The nodal
configurational forces :math:`g_i = \partial\Pi/\partial X_i` are one vector, UFL's coordinate
derivative of the free energy, and at a node of the outline
:math:`\mathcal{G}_i - w - \alpha = -g_i\cdot m_i/|m_i|^2` with :math:`m_i = \oint \phi_i\,\nu\,ds`,
the node's share of the outline's normal (exact for a uniform rate; corners get the mean
normal). For the circle the mean over the outline is the axisymmetric -∂Π/∂R1 / 2π.
"""

from __future__ import annotations

import math

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem.petsc import assemble_vector


def _assembled(form) -> np.ndarray:
    """The owned entries of the assembled vector of ``form`` (ghosts summed in)."""
    vector = assemble_vector(form)
    vector.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    values = vector.array_r.copy()
    vector.destroy()
    return values


class ReleaseRate:
    """The release rate at the outline's nodes of the current state (collective call).

    The mesh may move (a growing front): the outline's normals are taken anew at each call.

    Args:
        ctx: the context (its kinematics read the mesh's coordinates).
        energy: the free energy Π as a form, with the debonding cost's share (``WettedSubstrate``)
            and the pressure's work -p V (not a volume constraint's target, which is no energy).
        edge_facets: the outline's facets.
        cost: w + α, the cost of debonding a unit area: a number, or a function of the points
            (an (n, 2) array) for a patterned adhesion.
        scale: the cost's typical size (the front's tolerance is relative to it).
    """

    def __init__(self, ctx, energy, edge_facets, cost, scale: float):
        msh = ctx.mesh
        msh.topology.create_connectivity(1, 2)
        self.comm = msh.comm
        self.cost_at = cost if callable(cost) else (lambda points: np.full(len(points), float(cost)))
        self.cost = scale
        # vertex hats (P1) for the motions: a node's share spans its two outline edges, which
        # averages the P2 fields' alternation between vertices and midpoints
        W = fem.functionspace(msh, ("Lagrange", 1, (2,)))
        theta = ufl.TestFunction(W)
        self.forces = fem.form(ufl.derivative(energy, ufl.SpatialCoordinate(msh), theta))
        tags = np.zeros(msh.topology.index_map(1).size_local + msh.topology.index_map(1).num_ghosts, np.int32)
        tags[edge_facets] = 1
        from dolfinx.mesh import meshtags

        marker = meshtags(msh, 1, np.arange(len(tags), dtype=np.int32), tags)
        ds = ufl.Measure("ds", domain=msh, subdomain_data=marker)(1)
        self._share = fem.form(ufl.inner(ufl.FacetNormal(msh), theta) * ds)
        self.space = W
        self.bs = W.dofmap.index_map_bs
        self.owned = W.dofmap.index_map.size_local
        self.nodes = np.flatnonzero(np.linalg.norm(self._normals(), axis=1) > 0)

    def _normals(self) -> np.ndarray:
        return _assembled(self._share).reshape(-1, self.bs)[: self.owned]

    @property
    def share(self) -> np.ndarray:
        """m_i of this rank's outline nodes (the current outline's)."""
        return self._normals()[self.nodes]

    @property
    def points(self) -> np.ndarray:
        """The (X, Y) of this rank's outline nodes."""
        return self.space.tabulate_dof_coordinates()[self.nodes, :2]

    def excess(self) -> np.ndarray:
        """G - cost at this rank's outline nodes (their coordinates: ``points``)."""
        g = _assembled(self.forces).reshape(-1, self.bs)[: self.owned][self.nodes]
        share = self.share
        return -np.einsum("ij,ij->i", g, share) / np.einsum("ij,ij->i", share, share)

    def rates(self) -> np.ndarray:
        """G at this rank's outline nodes."""
        return self.excess() + self.cost_at(self.points)

    def __call__(self) -> dict:
        """``G_max``, ``G_mean`` (length-weighted) and ``G_min`` over the outline, in mu_f t0; the
        same of G - cost (``excess_max``, ``excess_mean``, ``excess_min``: the onset is where the
        largest reaches 0), and where it is largest (``front_x``, ``front_y``); and the outline's
        least and largest distance from the origin, the initial centroid (``front_R_min``,
        ``front_R_max``)."""
        points = self.points
        excess = self.excess()
        G = excess + self.cost_at(points)
        length = np.linalg.norm(self.share, axis=1)
        total = self.comm.allreduce(np.array([float(np.dot(G, length)), float(np.dot(excess, length)),
                                              float(length.sum())]), op=MPI.SUM)
        local = (float(excess.max()), *map(float, points[np.argmax(excess)])) if excess.size else (-math.inf, 0, 0)
        top = max(self.comm.allgather(local))
        radius = np.linalg.norm(points, axis=1)

        def extreme(values, op):
            return self.comm.allreduce(float(values.max(initial=-math.inf) if op is MPI.MAX
                                             else values.min(initial=math.inf)), op=op)

        return {"G_max": extreme(G, MPI.MAX), "G_mean": total[0] / total[2], "G_min": extreme(G, MPI.MIN),
                "excess_max": top[0], "excess_mean": total[1] / total[2], "excess_min": extreme(excess, MPI.MIN),
                "front_x": top[1], "front_y": top[2],
                "front_R_min": self.comm.allreduce(float(radius.min(initial=math.inf)), op=MPI.MIN),
                "front_R_max": self.comm.allreduce(float(radius.max(initial=-math.inf)), op=MPI.MAX)}

    def gather(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(points, G, cost) of the whole outline on every rank, ordered by angle about the
        centroid."""
        points = np.vstack(self.comm.allgather(self.points))
        G = np.concatenate(self.comm.allgather(self.rates()))
        order = np.argsort(np.arctan2(points[:, 1], points[:, 0]))
        return points[order], G[order], self.cost_at(points[order])
