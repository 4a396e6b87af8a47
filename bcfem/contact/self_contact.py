r"""Frictionless self-contact of a boundary curve of an axisymmetric solid (penalty).

A wall that creases, or a stiff lining that folds, must not pass through
itself. The boundary's nodes (the P2 or P1 nodes of its facets, joined into straight
segments) are checked against every segment that is not at or next to them:
a node p that has passed behind a segment (a, b) by the signed gap

.. math:: g = \frac{(b - a) \times (p - a)}{|b - a|} < 0,

(positive on the free side of the segment) is pushed back by the energy

.. math:: \Pi_c = \sum_p \tfrac{k}{2}\, w_p \langle -g_p \rangle^2, \qquad
          k = c_k\,\mu / L_{ab},\quad w_p = 2\pi R_p\,\ell_p,

with ℓ_p the reference length that node p stands for. The penalty makes the
penetration O(μ/k) = O(L/c_k) of the contact pressure over μ. A pair counts
only when p projects onto the segment, faces it (opposite normals) and lies
less than ``depth`` L behind it, so that a sharp fold of the solid (the
solid, not the free side, inside the fold) is not taken for contact. Whether a
node faces a segment is decided once per Newton solve, at its start: at the tip
of a fold the node's mean normal turns edge-on, and a test at every iterate
switched the pair on and off between iterates (a Newton 2-cycle).

A node that one Newton step carries deeper than ``depth`` L behind a segment
is out of the penalty's reach, and the wall would stay through itself (curled
into a loop through its own side). So the term also
vetoes a converged state whose boundary crosses itself that deep
(``inadmissible``): the solve fails, and the load step is cut back. A problem
may instead keep every Newton step short enough that the wall stays admissible
(``step_bound``, :meth:`bcfem.solver.problem.Problem.bound_steps`); the crater scene
does so when it traces a failed cycle again.

The pairs couple boundary nodes far apart in the mesh, so this term is not a
UFL form: it adds its residual and exact Hessian (frozen pairs) to the
assembled system through the problem's ``add_residual``/``add_jacobian``
hooks, on the nodes each rank owns. Every rank holds the whole boundary (O(10^2)
nodes for a crater wall); the pairs are searched on a bucket grid
(:mod:`bcfem.contact.search`), and the gap is evaluated for the nodes near a segment only.
"""

from __future__ import annotations

import math

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from dolfinx import fem

from bcfem.contact.gap import ROTATION, gap, gap_derivatives, gap_derivatives_batch
from bcfem.contact.search import overlapping_boxes, points_in_boxes
from bcfem.params import require
from bcfem.physics.protocols import DiscreteTerm

__all__ = ["WallSelfContact", "gap", "gap_derivatives"]

def _padded(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Boxes (lo, hi) around segments grown by 1e-6 of their largest coordinate. A box holds
    its segment, so this is at least 1e-6 of the segment's coordinates and 3e-7 of its
    length: far more than the rounding of the gap, of xi and of the corners, so that no pair
    the exact test accepts falls outside its box."""
    pad = 1e-6 * np.maximum(np.abs(lo), np.abs(hi)).max(axis=1, keepdims=True)
    return lo - pad, hi + pad


class WallSelfContact(DiscreteTerm):
    """Penalty self-contact of the boundary part ``boundary`` (a facet tag): a
    :class:`bcfem.physics.protocols.DiscreteTerm` with every hook.

    Args:
        facet_tags: the mesh's facet tags.
        boundary: tag (or tuple of tags) of the boundary that may touch itself.
        modulus: shear modulus of the stiffest material at that boundary (sets k).
        penalty: c_k, the penalty over μ/L (penetration ~ contact pressure / (c_k μ) L).
        depth: the deepest penetration taken for contact, in segment lengths.
    """

    symmetric_tangent = True  # the Hessian of the penalty energy
    name = "self_contact"
    #: (node, segment) pairs held together whatever the gap's sign (:meth:`bond`)
    bonded: tuple[np.ndarray, np.ndarray] = (np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))

    def __init__(self, facet_tags, boundary: int | tuple[int, ...], modulus: float, penalty: float = 1e3,
                 depth: float = 0.25):
        require(modulus > 0, f"self-contact modulus must be > 0 (got {modulus})")
        require(penalty > 0, f"self-contact penalty must be > 0 (got {penalty})")
        require(0 < depth < 1, f"self-contact depth must be in (0, 1) segment lengths (got {depth})")
        self.facet_tags, self.boundary = facet_tags, boundary
        self.modulus, self.penalty, self.depth = modulus, penalty, depth
        self.active = 0  # pairs in contact at the last evaluation
        #: (positions, facing, pairs) of the last search, reused while neither changes
        self._last_search: tuple | None = None
        self.facing: np.ndarray | None = None  # (owned nodes, segments): who faces whom, frozen per solve

    # -- set-up ---------------------------------------------------------------------------
    def bind(self, problem) -> None:
        """Find the boundary's nodes and segments and their global unknowns (once)."""
        u = problem.ctx.u
        V = u.function_space
        msh = V.mesh
        comm = msh.comm
        self.u, self.comm, self.scale = u, comm, problem.inverse_scale
        index = problem.global_indices("displacement")  # unrolled local dof -> global row
        fixed = problem.constrained("displacement")
        X = V.tabulate_dof_coordinates()[:, :2]
        owned_blocks = V.dofmap.index_map.size_local
        msh.topology.create_connectivity(1, 2)
        f_to_c = msh.topology.connectivity(1, 2)
        segments, nodes, midpoints = [], {}, set()
        tags = self.boundary if isinstance(self.boundary, tuple) else (self.boundary,)
        for f in np.concatenate([self.facet_tags.find(t) for t in tags]):
            blocks = fem.locate_dofs_topological(V, 1, np.array([f], dtype=np.int32), remote=False)
            pts = X[blocks]
            cell_blocks = V.dofmap.cell_dofs(f_to_c.links(f)[0])
            if len(blocks) == 2:  # a P1 (Q1) facet: one segment
                chain = list(blocks)
                inward = X[cell_blocks].mean(axis=0) - pts.mean(axis=0)  # towards the solid
            elif len(blocks) == 3:  # a P2 facet: two segments through its midpoint
                far = max(((i, j) for i in range(3) for j in range(i + 1, 3)),
                          key=lambda ij: np.linalg.norm(pts[ij[0]] - pts[ij[1]]))
                mid = 3 - sum(far)
                inward = X[cell_blocks].mean(axis=0) - pts[mid]  # towards the solid
                chain = [blocks[far[0]], blocks[mid], blocks[far[1]]]
                midpoints.add(index[2 * blocks[mid]])
            else:
                raise ValueError(f"self-contact needs P1 or P2 displacements (a facet with {len(blocks)} nodes)")
            for k0, k1 in zip(chain[:-1], chain[1:]):
                d = X[k1] - X[k0]
                if d[0] * inward[1] - d[1] * inward[0] > 0:  # solid on the left: swap
                    k0, k1 = k1, k0
                segments.append((index[2 * k0], index[2 * k1]))
            for k in chain:
                nodes[index[2 * k]] = (index[2 * k + 1], *X[k], fixed[2 * k], fixed[2 * k + 1])
        # every rank holds the whole boundary: nodes by their global r-row
        all_nodes: dict[int, list] = {}
        for part in comm.allgather(nodes):
            for key, (zrow, r, z, fr, fz) in part.items():
                entry = all_nodes.setdefault(key, [zrow, r, z, fr, fz])
                entry[3], entry[4] = entry[3] or fr, entry[4] or fz
        rows = np.array(sorted(all_nodes), dtype=np.int64)
        position = {row: i for i, row in enumerate(rows)}
        table = np.array([all_nodes[row] for row in rows], dtype=np.float64).reshape(-1, 5)
        self.rows = np.column_stack([rows, table[:, 0].astype(np.int64)])  # (n, 2) global rows (r, z)
        self.fixed = table[:, 3:5].astype(bool)
        self.X = table[:, 1:3]
        pairs = {tuple(s) for part in comm.allgather(segments) for s in part}
        self.segments = np.array(sorted((position[a], position[b]) for a, b in pairs), dtype=np.int64).reshape(-1, 2)
        # owned nodes: this rank computes their pairs and sends their positions
        local_rows = {index[2 * k]: k for k in range(owned_blocks)}
        self.owned = np.array([i for i, row in enumerate(rows) if row in local_rows], dtype=np.int64)
        self.owned_blocks = np.array([local_rows[rows[i]] for i in self.owned], dtype=np.int64)
        # every rank's owned nodes in rank order, and their coordinate counts: the layout of
        # one Allgatherv of the displacements (no pickling at every evaluation)
        self.gathered = np.concatenate(comm.allgather(self.owned))
        self.gather_counts = 2 * np.array(comm.allgather(self.owned.size))
        lengths = np.linalg.norm(self.X[self.segments[:, 1]] - self.X[self.segments[:, 0]], axis=1)
        self.segment_length = lengths
        # Simpson's weights on each P2 facet (1/6, 4/6, 1/6 of its length), the trapezoidal rule's
        # on a P1 one (1/2, 1/2): the nodal forces of a uniform contact pressure are then those
        # of the finite element
        middle = np.zeros(len(rows), dtype=bool)
        middle[[position[m] for part in comm.allgather(midpoints) for m in part]] = True
        quadratic = middle[self.segments].any(axis=1)  # a half of a P2 facet
        share = np.zeros(len(rows))
        for end in (0, 1):
            fraction = np.where(quadratic, np.where(middle[self.segments[:, end]], 2 / 3, 1 / 3), 1 / 2)
            np.add.at(share, self.segments[:, end], fraction * lengths)
        self.weight = 2 * math.pi * self.X[:, 0] * share
        n = len(rows)
        # a node projects onto a segment for xi in [0, 1); past the free end of the boundary
        # (a node where only one segment meets) the segment counts half a length further,
        # so that a node pressed at the very end does not drop out of contact
        ends = np.bincount(self.segments.reshape(-1), minlength=n) == 1
        self.xi_min = np.where(ends[self.segments[:, 0]], -0.5, 0.0)
        self.xi_max = np.where(ends[self.segments[:, 1]], 1.5, 1.0)
        # a node never touches a segment at or next to it
        neighbours: list[set[int]] = [set() for _ in range(n)]
        for a, b in self.segments:
            neighbours[a].update((a, b))
            neighbours[b].update((a, b))
        self.excluded = np.zeros((n, len(self.segments)), dtype=bool)
        for s, (a, b) in enumerate(self.segments):
            for i in neighbours[a] | neighbours[b]:
                self.excluded[i, s] = True
        problem.allow_new_nonzeros()

    # -- evaluation -----------------------------------------------------------------------
    def _positions(self, displacement: np.ndarray | None = None) -> np.ndarray:
        """Positions of all boundary nodes, on every rank: the current ones, or those for
        this rank's nodes' ``displacement`` ((owned, 2), gathered from every rank)."""
        if displacement is None:
            displacement = self.u.x.array.reshape(-1, 2)[self.owned_blocks]
        everyone = np.empty((len(self.gathered), 2))
        self.comm.Allgatherv(np.ascontiguousarray(displacement, dtype=float), [everyone, self.gather_counts])
        x = self.X.copy()
        x[self.gathered] += everyone  # each node is owned by one rank
        return x

    def step_bound(self, x: PETSc.Vec, y: PETSc.Vec, halvings: int = 10) -> float:
        """The largest t in 1, 1/2, ..., 2^-(halvings-1) for which Newton's update x - t y
        keeps the boundary admissible, else 2^-halvings (1 if x itself is not admissible:
        the veto then decides).

        A full step that carries a node deeper than ``depth`` L behind a segment leaves the
        penalty's window, and Newton can converge with the wall through itself; a shorter
        step keeps the pair in the window, where the penalty pushes it back.
        """
        start, end = x.getOwnershipRange()
        local = self.rows[self.owned] - start
        assert local.size == 0 or (local.min() >= 0 and local.max() < end - start)
        here = self._positions(x.array[local])
        if self.inadmissible(here) is not None:
            return 1.0
        step = self._positions(y.array[local]) - self.X
        t = 1.0
        for _ in range(halvings):
            if self.inadmissible(here - t * step) is None:
                return t
            t *= 0.5
        return t

    def _facing(self, x: np.ndarray) -> np.ndarray:
        """(owned nodes x segments): the node's mean normal opposes the segment's."""
        seg = self.segments
        d = x[seg[:, 1]] - x[seg[:, 0]]
        seg_normal = (ROTATION @ d.T).T / np.linalg.norm(d, axis=1)[:, None]
        node_normal = np.zeros_like(x)
        np.add.at(node_normal, seg[:, 0], seg_normal)
        np.add.at(node_normal, seg[:, 1], seg_normal)
        return node_normal[self.owned] @ seg_normal.T < 0

    def begin_solve(self) -> None:
        """Freeze who faces whom at the state a Newton solve starts from."""
        self.facing = self._facing(self._positions())

    def _windows(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) corners of the box around each segment's window: where a node
        projects onto it (xi in [xi_min, xi_max]) and lies at most ``depth`` L behind it."""
        d = b - a
        start, end = a + self.xi_min[:, None] * d, a + self.xi_max[:, None] * d
        behind = self.depth * d[:, ::-1] * (1.0, -1.0)  # depth L along the normal into the solid
        return _padded(np.minimum(start, end) + np.minimum(behind, 0.0),
                       np.maximum(start, end) + np.maximum(behind, 0.0))

    def tangent_key(self) -> tuple:
        """What the tangent depends on besides the states: who faces whom and the bonds."""
        facing = np.zeros((0, 0), dtype=bool) if self.facing is None else self.facing
        return (facing, *self.bonded)

    def bond(self, nodes: np.ndarray, segments: np.ndarray) -> None:
        """Hold these (owned node, segment) pairs together from now on: the penalty acts on
        their gap to the segment's line in both directions (frictionless: the node slides
        along it), so that the contact cannot open (non-separable contact)."""
        self.bonded = (np.asarray(nodes, dtype=np.int64), np.asarray(segments, dtype=np.int64))
        self._last_search = None

    def contacts(self):
        """:meth:`pairs` at the current positions (collective: the positions are gathered)."""
        return self.pairs(self._positions())

    def pairs(self, x: np.ndarray):
        """The contacts of this rank's nodes: (node, segment, gap) arrays, by node and then
        segment.

        Only the (node, segment) pairs whose node lies in the box around the segment's
        window (:func:`bcfem.contact.search.points_in_boxes`) are tested: a contact lies
        in that window, so the pairs are those of a test of every combination. Newton
        assembles the tangent at the state of the last residual, so the last search is
        kept and reused while the positions and who faces whom are the same.
        """
        last = self._last_search
        if last is not None and last[1] is self.facing and np.array_equal(last[0], x):
            return last[2]
        found = self._with_bonds(x, *self._search(x))
        self._last_search = (x.copy(), self.facing, found)
        return found

    def _with_bonds(self, x: np.ndarray, P: np.ndarray, S: np.ndarray, g: np.ndarray):
        """The pairs found, and the bonded pairs not among them (with their gap, of either sign)."""
        bP, bS = self.bonded
        if bP.size == 0:
            return P, S, g
        new = ~np.isin(bP * len(self.segments) + bS, P * len(self.segments) + S)
        bP, bS = bP[new], bS[new]
        bg, _ = gap(x[bP], x[self.segments[bS, 0]], x[self.segments[bS, 1]])
        P, S, g = np.concatenate([P, bP]), np.concatenate([S, bS]), np.concatenate([g, bg])
        order = np.argsort(P * len(self.segments) + S, kind="stable")
        return P[order], S[order], g[order]

    def _search(self, x: np.ndarray):
        """:meth:`pairs`, searched afresh."""
        seg = self.segments
        nodes = self.owned
        empty = np.zeros(0, dtype=np.int64)
        if nodes.size == 0 or seg.size == 0:
            return empty, empty, np.zeros(0)
        a, b = x[seg[:, 0]], x[seg[:, 1]]
        nodes = nodes[self.weight[nodes] > 0]  # a weightless node carries no force
        i, S = points_in_boxes(x[nodes], *self._windows(a, b))
        P = nodes[i]
        # a node is in the windows of its own segments, which it never touches: most often
        # no candidate is left
        apart = ~self.excluded[P, S]
        if not apart.any():
            return empty, empty, np.zeros(0)
        P, S = P[apart], S[apart]
        order = np.argsort(P * len(seg) + S)  # as the nodes' loop over the segments
        P, S = P[order], S[order]
        facing = self._facing(x) if self.facing is None else self.facing
        row = np.empty(len(x), dtype=np.int64)  # node -> its row in ``facing``
        row[self.owned] = np.arange(self.owned.size)
        a, b = a[S], b[S]
        g, xi = gap(x[P], a, b)
        hit = ((g <= 0) & (g > -self.depth * np.linalg.norm(b - a, axis=1)) & (xi >= self.xi_min[S])
               & (xi < self.xi_max[S]) & facing[row[P], S])
        return P[hit], S[hit], g[hit]

    def inadmissible(self, x: np.ndarray | None = None) -> str | None:
        """Where the boundary (at the current positions, or at ``x``) passes through itself
        beyond the penalty's reach, or None.

        Two segments that cross while the node behind each lies less than ``depth`` L
        behind the other are a contact the penalty holds (penetration O(L/c_k)). Deeper,
        the pair has left the window the penalty acts in and nothing pushes it back: the
        wall has gone through itself, and its crater volume counts the overlap negatively.
        """
        x = self._positions() if x is None else x
        seg = self.segments
        # segments that cross overlap: only the pairs of overlapping boxes are tested, in
        # the order of every pair (the first deepest crossing is reported)
        p, q = x[seg[:, 0]], x[seg[:, 1]]
        i, j = overlapping_boxes(*_padded(np.minimum(p, q), np.maximum(p, q)))
        apart = (seg[i, 0] != seg[j, 0]) & (seg[i, 0] != seg[j, 1]) & (seg[i, 1] != seg[j, 0]) \
            & (seg[i, 1] != seg[j, 1])
        i, j = i[apart], j[apart]
        p, q, a, b = x[seg[i, 0]], x[seg[i, 1]], x[seg[j, 0]], x[seg[j, 1]]
        g_p, _ = gap(p, a, b)
        g_q, _ = gap(q, a, b)
        g_a, _ = gap(a, p, q)
        g_b, _ = gap(b, p, q)
        cross = (g_p * g_q < 0) & (g_a * g_b < 0)
        if not cross.any():
            return None
        # the depth of the crossing: how far the endpoint behind each segment lies behind it
        behind_j = -np.minimum(g_p, g_q) / np.linalg.norm(b - a, axis=1)
        behind_i = -np.minimum(g_a, g_b) / np.linalg.norm(q - p, axis=1)
        depth = np.where(cross, np.minimum(behind_i, behind_j), 0.0)
        worst = int(np.argmax(depth))
        if depth[worst] <= self.depth:
            return None
        r, z = 0.5 * (p[worst] + q[worst])
        return (f"the boundary passes through itself near (r, z) = ({r:.4g}, {z:.4g}), "
                f"{depth[worst]:.2f} segment lengths deep (the self-contact acts to {self.depth:g})")

    def _stiffness(self, P: np.ndarray, S: np.ndarray) -> np.ndarray:
        """k w_p of each pair (node P, segment S)."""
        return self.penalty * self.modulus / self.segment_length[S] * self.weight[P]

    def penalty_energy(self) -> float:
        """Π_c at the current states, over the pairs the residual sees (unscaled; on
        every rank, collective)."""
        P, S, g = self.pairs(self._positions())
        return self.comm.allreduce(float(np.sum(0.5 * self._stiffness(P, S) * g**2)), op=MPI.SUM)

    def _contributions(self, with_hessian: bool):
        """(rows (n, 6), free (n, 6), forces (n, 6), tangents (n, 6, 6) or None) of the pairs
        in contact, all at once."""
        x = self._positions()
        P, S, g = self.pairs(x)
        self.active = self.comm.allreduce(len(P), op=MPI.SUM)
        nodes = np.stack([P, self.segments[S, 0], self.segments[S, 1]], axis=1)  # (n, 3)
        rows = self.rows[nodes].reshape(len(P), 6)
        free = ~self.fixed[nodes].reshape(len(P), 6)
        if len(P) == 0:  # most evaluations: the derivatives' set-up alone would cost more
            return rows, free, np.zeros((0, 6)), np.zeros((0, 6, 6)) if with_hessian else None
        grad, hess = gap_derivatives_batch(x[P], x[nodes[:, 1]], x[nodes[:, 2]])
        k = float(self.scale.value) * self._stiffness(P, S)
        force = (k * g)[:, None] * grad
        tangent = k[:, None, None] * (np.einsum("ni,nj->nij", grad, grad) + g[:, None, None] * hess) \
            if with_hessian else None
        return rows, free, force, tangent

    def add_residual(self, b: PETSc.Vec) -> None:
        """b += dΠ_c/du (free rows only; Dirichlet rows hold their own equation)."""
        rows, free, force, _ = self._contributions(False)
        b.setValues(rows[free].astype(PETSc.IntType), force[free], addv=PETSc.InsertMode.ADD_VALUES)
        b.assemblyBegin()
        b.assemblyEnd()

    def add_jacobian(self, A: PETSc.Mat) -> None:
        """A += d²Π_c/du² (free rows and columns only)."""
        rows, free, _, tangents = self._contributions(True)
        for r, f, tangent in zip(rows, free, tangents):
            idx = r[f].astype(PETSc.IntType)
            A.setValues(idx, idx, tangent[np.ix_(f, f)], addv=PETSc.InsertMode.ADD_VALUES)
        A.assemble()
