r"""A virtual membrane that divides a double-chamber crater into two chambers from the start.

The dissertation's Abaqus model (§9.2) joins a node of the protuberance (Node-1, current
position x_b) and a node of the sidewall (Node-2, x_w) by a membrane element: the surface of
revolution of the segment between them (the plug of :mod:`bcfem.scenes.crater_double.chambers`) closes C1 below and
C2 above it while the two walls are still apart. C1 and C2 then take the walls cut at the two
nodes plus the plug's flux P(x_b, x_w) of z e_z, with the sign of :func:`bcfem.scenes.crater_double.chambers.plug_flux`:

.. math:: V_{C1} = V_{C1}^{walls} + P, \qquad V_{C2} = V_{C2}^{walls} - P, \qquad
          P = \tfrac{\pi}{3}(r_w - r_b)\,(2 r_b z_b + r_b z_w + r_w z_b + 2 r_w z_w),

so the pressures do the work :math:`-(p_1 - 1) P + (p_2 - 1) P` on it. The membrane may also
carry a small stiffness: a ring membrane of reference area A0 = 2π R̄ L0 (R̄ the mean radius,
L0 the segment's length) in Saint Venant-Kirchhoff form with zero Poisson's ratio,

.. math:: \Pi = -(p_1 - p_2)\,P(x_b, x_w) + k A_0 (E_{11}^2 + E_{22}^2), \quad
          E_{11} = \tfrac12 (L^2/L_0^2 - 1),\quad E_{22} = \tfrac12 (\bar r^2/\bar R^2 - 1),

with k = μ_m t (a membrane modulus times its thickness). Π is a polynomial of four nodal
coordinates and two pressures, not one form over the mesh: it is a
:class:`bcfem.physics.protocols.DiscreteTerm`, its gradient and exact Hessian added to the assembled
system. With one pressure (the chambers still one cavity) only the stiffness acts.
"""

from __future__ import annotations

import math

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from bcfem.mpi import real_value
from bcfem.physics.protocols import DiscreteTerm

#: the Hessian of Q = 2 r_b z_b + r_b z_w + r_w z_b + 2 r_w z_w in (r_b, z_b, r_w, z_w)
_HQ = np.array([[0, 2, 0, 1], [2, 0, 1, 0], [0, 1, 0, 2], [1, 0, 2, 0]], dtype=float)
_E = np.array([-1.0, 0.0, 1.0, 0.0])  # d(r_w - r_b)
_HL = np.array([[1, 0, -1, 0], [0, 1, 0, -1], [-1, 0, 1, 0], [0, -1, 0, 1]], dtype=float)  # of L^2 / 2
_ER = np.array([1.0, 0.0, 1.0, 0.0])


def plug(x: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """P, its gradient and Hessian in x = (r_b, z_b, r_w, z_w)."""
    rb, zb, rw, zw = x
    d = rw - rb
    Q = 2 * rb * zb + rb * zw + rw * zb + 2 * rw * zw
    dQ = np.array([2 * zb + zw, 2 * rb + rw, zb + 2 * zw, rb + 2 * rw])
    c = math.pi / 3
    return c * d * Q, c * (d * dQ + Q * _E), c * (np.outer(_E, dQ) + np.outer(dQ, _E) + d * _HQ)


def ring_membrane(x: np.ndarray, X: np.ndarray, stiffness: float) -> tuple[float, np.ndarray, np.ndarray]:
    """k A0 (E11^2 + E22^2), its gradient and Hessian in x (reference X, k = ``stiffness``)."""
    dX, dx = X[2:] - X[:2], x[2:] - x[:2]
    L0sq, R = float(dX @ dX), 0.5 * (X[0] + X[2])
    area = 2 * math.pi * R * math.sqrt(L0sq)
    E11 = 0.5 * (float(dx @ dx) / L0sq - 1)
    g11 = np.concatenate([-dx, dx]) / L0sq
    rbar = 0.5 * (x[0] + x[2])
    E22 = 0.5 * (rbar**2 / R**2 - 1)
    g22 = rbar / (2 * R**2) * _ER
    scale = 2 * stiffness * area
    energy = stiffness * area * (E11**2 + E22**2)
    grad = scale * (E11 * g11 + E22 * g22)
    hess = scale * (np.outer(g11, g11) + E11 * _HL / L0sq + np.outer(g22, g22) + E22 * np.outer(_ER, _ER) / (4 * R**2))
    return energy, grad, hess


class ChamberMembrane(DiscreteTerm):
    """The membrane between a protuberance node and a sidewall node (a
    :class:`bcfem.physics.protocols.DiscreteTerm`).

    Args:
        protuberance_point, sidewall_point: the two nodes' reference positions (R, Z).
        pressures: the chambers' pressure states (C1, C2), or None while they are one cavity.
        stiffness: k = μ_m t, in the problem's units (pressure times length); 0: none.
        tolerance: how far from a given point its mesh node may lie.
    """

    symmetric_tangent = True  # the Hessian of Π in (x, p)
    name = "chamber_membrane"

    def __init__(self, protuberance_point, sidewall_point, pressures: tuple[str, str] | None = None,
                 stiffness: float = 0.0, tolerance: float = 1e-9):
        self.X = np.array([*protuberance_point, *sidewall_point], dtype=float)
        self.pressures, self.stiffness, self.tolerance = pressures, stiffness, tolerance

    def attach(self, u) -> None:
        """Find the two nodes among the displacement's owned dofs (collective)."""
        V = u.function_space
        self.u, self.comm = u, V.mesh.comm
        coords = V.tabulate_dof_coordinates()[: V.dofmap.index_map.size_local, :2]
        self.blocks: list[int | None] = [None, None]
        for i, point in enumerate((self.X[:2], self.X[2:])):
            near = np.flatnonzero(np.linalg.norm(coords - point, axis=1) < self.tolerance)
            self.blocks[i] = int(near[0]) if near.size else None
        if self.comm.allreduce(sum(k is not None for k in self.blocks), op=MPI.SUM) != 2:
            raise ValueError(f"chamber membrane: no mesh node at {self.X.reshape(2, 2).tolist()}")

    def bind(self, problem) -> None:
        """Find the two nodes' global rows and the pressures' rows (on every rank)."""
        self.attach(problem.ctx.u)
        self.scale, self.ctx = problem.inverse_scale, problem.ctx
        index, fixed = problem.global_indices("displacement"), problem.constrained("displacement")
        # each node is owned by one rank: the others add zeros
        found, free = np.zeros(4, dtype=np.int64), np.zeros(4, dtype=np.int64)
        for i, k in enumerate(self.blocks):
            if k is not None:
                found[2 * i:2 * i + 2] = index[2 * k:2 * k + 2]
                free[2 * i:2 * i + 2] = ~fixed[2 * k:2 * k + 2]
        self.rows = self.comm.allreduce(found, op=MPI.SUM)
        self.free = self.comm.allreduce(free, op=MPI.SUM).astype(bool)
        self.pressure_rows = None
        if self.pressures:
            self.pressure_rows = np.array([self.comm.allreduce(int(problem.global_indices(n).max(initial=-1)),
                                                               op=MPI.MAX) for n in self.pressures])
        problem.allow_new_nonzeros()

    def positions(self) -> np.ndarray:
        """(r_b, z_b, r_w, z_w) now, on every rank (collective)."""
        mine = np.zeros(4)
        values = self.u.x.array.reshape(-1, 2)
        for i, k in enumerate(self.blocks):
            if k is not None:
                mine[2 * i:2 * i + 2] = values[k]
        return self.X + self.comm.allreduce(mine, op=MPI.SUM)

    def plug_volume(self) -> float:
        """P at the current state: what the plug adds to V_C1 and takes from V_C2 (collective)."""
        return plug(self.positions())[0]

    def _derivatives(self):
        """(rows, gradient, Hessian) of Π in (x, p1, p2) or in x alone."""
        x = self.positions()
        energy, grad, hess = ring_membrane(x, self.X, self.stiffness) if self.stiffness > 0 else \
            (0.0, np.zeros(4), np.zeros((4, 4)))
        if not self.pressures:
            return self.rows, self.free, grad, hess
        p1, p2 = (real_value(self.ctx.states[n]) for n in self.pressures)
        P, dP, HP = plug(x)
        g = np.concatenate([grad - (p1 - p2) * dP, [-P, P]])
        H = np.zeros((6, 6))
        H[:4, :4] = hess - (p1 - p2) * HP
        H[:4, 4], H[:4, 5] = -dP, dP
        H[4, :4], H[5, :4] = -dP, dP
        return np.concatenate([self.rows, self.pressure_rows]), np.concatenate([self.free, [True, True]]), g, H

    def add_residual(self, b: PETSc.Vec) -> None:
        rows, free, g, _ = self._derivatives()
        if self.comm.rank == 0:  # every rank knows it; one adds it
            b.setValues(rows[free].astype(PETSc.IntType), float(self.scale.value) * g[free],
                        addv=PETSc.InsertMode.ADD_VALUES)
        b.assemblyBegin()
        b.assemblyEnd()

    def add_jacobian(self, A: PETSc.Mat) -> None:
        rows, free, _, H = self._derivatives()
        if self.comm.rank == 0:
            idx = rows[free].astype(PETSc.IntType)
            A.setValues(idx, idx, float(self.scale.value) * H[np.ix_(free, free)], addv=PETSc.InsertMode.ADD_VALUES)
        A.assemble()
