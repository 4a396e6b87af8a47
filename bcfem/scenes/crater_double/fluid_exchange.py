r"""Fluid exchange between two sealed ideal-gas chambers: eq. 9.1 of the dissertation.

Abaqus's fluid exchange with a viscous resistance C_V (§9.2):

.. math:: (p_1 - p_2) A = C_V \dot m,

ṁ the mass flowing from chamber 1 to 2. Normalised here: pressures in p_a, masses as p V
(isothermal ideal gas, m = p V in units of p_a times the length unit cubed), the exchange area
folded into C_V (A = 1 length unit squared), and time the load step's pseudo-time t (Abaqus's
static step: t = ε/ε0 while loading to ε0). Backward Euler over a step Δt from the masses
m_i⁰ of the last accepted state gives, with c = Δt / C_V,

.. math:: p_1 V_1 = m_1^0 - c (p_1 - p_2), \qquad p_2 V_2 = m_2^0 + c (p_1 - p_2):

m_1 + m_2 is conserved exactly at every step; c = 0 is two sealed chambers, c → ∞ one. Each
chamber's :class:`bcfem.physics.fluids.IdealGas` (sealed amount m_i⁰) gives the row -V_i + m_i⁰/p_i;
this term adds ∓c (p_1 - p_2)/p_i to it. The law is dissipative, not the derivative of an
energy (a potential would give ln(p1/p2) for the linear p_1 - p_2), so this is a
:class:`bcfem.physics.protocols.DiscreteTerm` with a non-symmetric 2 × 2 tangent.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from bcfem.mpi import real_value
from bcfem.physics.protocols import DiscreteTerm


class FluidExchange(DiscreteTerm):
    """Backward-Euler exchange between the chambers ``pressures`` = (p1, p2) (a DiscreteTerm).

    Attributes:
        conductance: c = Δt / C_V of the step being solved (set by the stage before each solve).
    """

    symmetric_tangent = False
    name = "fluid_exchange"

    def __init__(self, pressures: tuple[str, str], conductance: float = 0.0):
        self.pressures, self.conductance = pressures, conductance

    def bind(self, problem) -> None:
        self.ctx, self.scale, self.comm = problem.ctx, problem.inverse_scale, problem.comm
        self.rows = np.array([self.comm.allreduce(int(problem.global_indices(n).max(initial=-1)), op=MPI.MAX)
                              for n in self.pressures], dtype=PETSc.IntType)
        problem.allow_new_nonzeros()

    def _values(self):
        p1, p2 = (real_value(self.ctx.states[n]) for n in self.pressures)
        return p1, p2, self.conductance * float(self.scale.value)

    def add_residual(self, b: PETSc.Vec) -> None:
        p1, p2, c = self._values()
        if self.comm.rank == 0:
            b.setValues(self.rows, [-c * (p1 - p2) / p1, c * (p1 - p2) / p2], addv=PETSc.InsertMode.ADD_VALUES)
        b.assemblyBegin()
        b.assemblyEnd()

    def add_jacobian(self, A: PETSc.Mat) -> None:
        p1, p2, c = self._values()
        if self.comm.rank == 0:
            J = c * np.array([[-p2 / p1**2, 1 / p1], [1 / p2, -p1 / p2**2]])
            A.setValues(self.rows, self.rows, J, addv=PETSc.InsertMode.ADD_VALUES)
        A.assemble()
