"""Problem: a failed Newton solve is retried with the line-search fallbacks, and the
user's line search wins over them.

The global unknown x solves arctan(x) = 0 (energy x arctan x - ln(1 + x^2)/2). Full
Newton steps from |x0| > 1.39 overshoot further at every step; backtracking converges.
"""

import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI
from petsc4py import PETSc

from bcfem import Context
from bcfem.problem import Problem

pytestmark = pytest.mark.mpi


class Arctan:
    def energy(self, ctx):
        x = ctx.real_state("x")
        return (x * ufl.atan(x) - 0.5 * ufl.ln(1 + x**2) + 0.5 * ctx.u**2) * ufl.dx


def solve_from(x0, **kwargs):
    msh = mesh.create_unit_interval(MPI.COMM_WORLD, 4)
    ctx = Context(fem.Function(fem.functionspace(msh, ("Lagrange", 1))))
    with Problem(ctx, [Arctan()], [], "bcfem_test_fallback_", {"snes_max_it": 40}, **kwargs) as problem:
        problem.state("x").x.array[:] = x0
        ok = problem.solve()
        return ok, float(problem.state("x").x.array[0]), problem.reason


def test_full_newton_fails_and_restores_the_state():
    ok, x, reason = solve_from(2.0)
    assert not ok and reason < 0
    assert x == 2.0


def test_backtracking_fallback_converges():
    ok, x, reason = solve_from(2.0, line_search_fallbacks=("bt",))
    assert ok and reason > 0
    assert abs(x) < 1e-10


def test_the_users_line_search_wins():
    opts = PETSc.Options()
    opts["bcfem_test_fallback_snes_linesearch_type"] = "basic"
    try:
        ok, x, _ = solve_from(2.0, line_search_fallbacks=("bt",))
    finally:
        opts.delValue("bcfem_test_fallback_snes_linesearch_type")
    assert not ok and x == 2.0
