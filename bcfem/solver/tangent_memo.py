"""The tangent assembled once per state: a stability count and the next Newton solve share it.

After a step converges, the stability count assembles J at the converged state, and the next
load step's Newton solve starts from that same state: a load moved through Dirichlet values
(a platen) leaves J as it was, so its first Jacobian would be the same matrix again. The memo
keeps what the last assembly saw and tells when the matrix still holds J.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from ufl.algorithms.analysis import extract_coefficients, extract_constants


class TangentMemo:
    """What the last assembly of a Jacobian matrix saw: the iterate, the values of the forms'
    other coefficients and constants (a viscosity, a previous state, a fluid's amount) and the
    discrete terms' ``tangent_key()``. A discrete term whose key is None (the default) makes
    every assembly anew.

    Args:
        forms: the UFL residual forms, whose coefficients and constants the Jacobian reads.
        states: the problem's states, which the iterate holds (not compared as coefficients).
        discrete: the problem's discrete terms.
        comm: the problem's communicator (the answer is the same on every rank).
    """

    def __init__(self, forms, states, discrete, comm):
        state_ids = {id(s) for s in states}
        coefficients, constants = {}, {}
        for form in forms:
            for c in extract_coefficients(form):
                if id(c) not in state_ids:
                    coefficients[id(c)] = c
            for c in extract_constants(form):
                constants[id(c)] = c
        self._coefficients = list(coefficients.values())
        self._constants = list(constants.values())
        self._discrete = list(discrete)
        self._comm = comm
        self._seen = None
        #: assemblies skipped because the matrix still held J
        self.reused = 0

    def _now(self, x: PETSc.Vec):
        keys = [t.tangent_key() for t in self._discrete]
        if any(k is None for k in keys):
            return None
        return ([x.array_r.copy()] + [c.x.array.copy() for c in self._coefficients]
                + [np.array(c.value, copy=True) for c in self._constants]
                + [np.array(a, copy=True) for k in keys for a in k])

    def stale(self, x: PETSc.Vec, J: PETSc.Mat) -> bool:
        """Whether ``J`` must be assembled at ``x``: it holds another state's Jacobian, or
        other values (collective). Else the assembly is skipped and counted in :attr:`reused`.
        The caller assembles ``J`` at ``x`` when True, or calls :meth:`forget` if it fails."""
        now, seen = self._now(x), self._seen
        same = (now is not None and seen is not None and seen[0] == J.handle and len(now) == len(seen[1])
                and all(a.shape == b.shape and np.array_equal(a, b) for a, b in zip(now, seen[1])))
        same = self._comm.allreduce(same, op=MPI.LAND)
        if same:
            self.reused += 1
            return False
        self._seen = None if now is None else (J.handle, now)
        return True

    def forget(self) -> None:
        """The next assembly is made anew."""
        self._seen = None
