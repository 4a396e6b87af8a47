"""The SNES callbacks of a problem: dolfinx's forms, then the discrete terms, both timed.

Two shortcuts keep work out of the Newton loop, and neither changes a number: the residual is
lifted only by the Dirichlet conditions whose values the iterate misses
(:mod:`bcfem.solver.unlifted`), and a Jacobian already assembled at the same state is not assembled
again (:mod:`bcfem.solver.tangent_memo`).
"""

from __future__ import annotations

from time import perf_counter

from bcfem.solver.tangent_memo import TangentMemo
from bcfem.solver.unlifted import UnliftedResidual


class Assembly:
    """Replaces the residual and Jacobian callbacks dolfinx gave ``problem.snes``.

    Args:
        problem: the :class:`~bcfem.solver.problem.Problem` (its discrete terms, timings, states).
        residuals: its UFL residual forms (their coefficients and constants key the memo).
    """

    def __init__(self, problem, residuals):
        self.problem = problem
        snes = problem.snes
        b, (self._residual, self._args, self._kargs) = snes.getFunction()
        A, P, (self._jacobian, self._jargs, self._jkargs) = snes.getJacobian()
        self.unlifted = UnliftedResidual(b, **self._kargs) if b.getAttr("_blocks") is not None else None
        self.memo = TangentMemo(residuals, problem.states, problem.discrete, problem.comm)
        #: residuals lifted (x off some Dirichlet values)
        self.liftings = 0
        #: tangents assembled (not those the memo found held already)
        self.tangents = 0
        snes.setFunction(self.function, b)
        snes.setJacobian(self.tangent, A, P)

    def _count(self, t0: float, t1: float) -> None:
        problem = self.problem
        if not problem._timing_outside:
            problem.timings["assembly"] += t1 - t0
            problem.timings["discrete_terms"] += perf_counter() - t1

    def function(self, snes, x, f) -> None:
        t0 = perf_counter()
        if self.unlifted is None:
            self._residual(snes, x, f, *self._args, **self._kargs)
            self.liftings += 1
        else:
            self.liftings += self.unlifted(x, f)
        t1 = perf_counter()
        for term in self.problem.discrete:
            term.add_residual(f)
        self._count(t0, t1)
        self.problem._guard_divergence(f)

    def tangent(self, snes, x, J, P) -> None:
        if P.handle == J.handle and not self.memo.stale(x, J):
            return
        t0 = perf_counter()
        try:
            self._jacobian(snes, x, J, P, *self._jargs, **self._jkargs)
            t1 = perf_counter()
            for term in self.problem.discrete:
                term.add_jacobian(J)
        except BaseException:
            self.memo.forget()
            raise
        self.tangents += 1
        self._count(t0, t1)

    def destroy(self) -> None:
        """Free the work vector (collective); the SNES keeps the callbacks."""
        if self.unlifted is not None:
            self.unlifted.destroy()
            self.unlifted = None
        self.problem = None
