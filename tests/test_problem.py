"""Problem: a failed Newton solve is retried with the line-search fallbacks, and the
user's line search wins over them; a variational-inequality SNES that claims convergence
without an equilibrium is caught; a term can reject a converged state.

The global unknown x solves arctan(x) = 0 (energy x arctan x - ln(1 + x^2)/2). Full
Newton steps from |x0| > 1.39 overshoot further at every step; backtracking converges.
"""

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from dolfinx.fem.petsc import NonlinearProblem

from bcfem import Context, Term
from bcfem.physics.protocols import DiscreteTerm
from bcfem.solver.problem import Problem

pytestmark = pytest.mark.mpi


class Arctan(Term):
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


class Obstacle(Term):
    """(u - (x - 1/2))^2/2 + u^4/2 over u >= 0: u = 0 on x < 1/2, positive beyond. Vertex
    quadrature decouples the nodes, so the discrete solution is the pointwise one."""

    def energy(self, ctx):
        x = ufl.SpatialCoordinate(ctx.mesh)
        dx = ufl.dx(metadata={"quadrature_rule": "vertex", "quadrature_degree": 1})
        return (0.5 * (ctx.u - (x[0] - 0.5)) ** 2 + 0.5 * ctx.u**4) * dx


class Silent(DiscreteTerm):
    """A discrete term that adds nothing to the residual and the tangent (and declares neither
    a symmetric tangent nor a tangent key)."""

    def bind(self, problem):
        pass

    def add_residual(self, b):
        pass

    def add_jacobian(self, A):
        pass


def solve_obstacle(snes_type, extra=(), factor=None):
    msh = mesh.create_unit_interval(MPI.COMM_WORLD, 8)
    V = fem.functionspace(msh, ("Lagrange", 1))
    ctx = Context(fem.Function(V))
    with Problem(ctx, [Obstacle(), *extra], [], "bcfem_test_vi_", {"snes_type": snes_type}) as problem:
        lower, upper = fem.Function(V), fem.Function(V)
        upper.x.array[:] = 1e20
        problem.set_bounds([lower], [upper])
        ok = problem.solve()
        if factor is not None:
            factor.append(problem.snes.getKSP().getPC().getPythonContext().ksp.getPC().getType())
        x = V.tabulate_dof_coordinates()[:, 0]
        return ok, problem.iterations, x, ctx.u.x.array.copy()


def test_the_obstacle_problem_is_solved_with_its_contact_set():
    ok, iterations, x, u = solve_obstacle("vinewtonrsls")
    assert ok and iterations > 0
    assert np.all(u[x <= 0.5] == 0.0)
    # u + 2u^3 = x - 1/2 where u > 0
    free = x > 0.5
    assert np.all(u[free] > 0)
    assert np.allclose(u[free] + 2 * u[free] ** 3, x[free] - 0.5, atol=1e-9)


@pytest.mark.parametrize("extra, expected", [((), "cholesky"), ((Silent(),), "lu")])
def test_a_symmetric_tangent_is_factorised_as_ldlt(extra, expected):
    # every term an energy: LDL^T; a discrete term that does not say so: LU. Same solution.
    factor = []
    ok, _, x, u = solve_obstacle("vinewtonrsls", extra, factor)
    assert ok and factor == [expected]
    free = x > 0.5
    assert np.all(u[~free] == 0.0)
    assert np.allclose(u[free] + 2 * u[free] ** 3, x[free] - 0.5, atol=1e-9)


def test_a_vi_convergence_in_zero_iterations_off_equilibrium_is_an_error():
    # vinewtonssls reports a zero norm at the start here (and did so in the crater): without
    # the check, u = 0 would be accepted
    with pytest.raises(RuntimeError, match="0 iterations.*vinewtonrsls"):
        solve_obstacle("vinewtonssls")


class Saddle(Term):
    """(w u^2/2 - u) with w = +1 on x < 1/2 and -1 beyond, on two DG0 cells: an indefinite
    tangent. From u = 0 the Newton step Y has dot(F, Y) = 0 exactly although F != 0, which
    PETSc's cp line search takes for a critical point and reports as CONVERGED_FNORM_ABS."""

    def energy(self, ctx):
        x = ufl.SpatialCoordinate(ctx.mesh)
        w = ufl.conditional(ufl.lt(x[0], 0.5), 1.0, -1.0)
        return (0.5 * w * ctx.u**2 - ctx.u) * ufl.dx


def solve_saddle(line_search):
    msh = mesh.create_unit_interval(MPI.COMM_WORLD, 2)
    V = fem.functionspace(msh, ("DG", 0))
    ctx = Context(fem.Function(V))
    with Problem(ctx, [Saddle()], [], "bcfem_test_cp_", {"snes_linesearch_type": line_search}) as problem:
        ok = problem.solve()
        x = V.tabulate_dof_coordinates()[:, 0]
        return ok, problem.critical_point_exits, problem.snes.getFunctionNorm(), x, ctx.u.x.array.copy()


@pytest.mark.parametrize("line_search", ["basic", "cp"])
def test_the_saddle_is_solved_also_where_cp_stops_at_a_critical_point(line_search):
    # from u = 0 PETSc's cp stops with CONVERGED_FNORM_ABS and u = 0 (no equilibrium);
    # accepted, u = 0 would pass as the solution. Newton steps finish from where it stopped.
    ok, exits, norm, x, u = solve_saddle(line_search)
    assert ok and norm < 1e-10
    assert np.allclose(u, np.where(x < 0.5, 1.0, -1.0), atol=1e-12)
    assert exits == (1 if line_search == "cp" else 0)


class Veto(Silent):
    """Rejects the converged state when told to (as the self-contact does a wall through
    itself)."""

    message = None

    def inadmissible(self):
        return self.message


@pytest.mark.parametrize("x0", [-0.5, 0.5])
def test_a_term_can_reject_a_converged_state(x0):
    msh = mesh.create_unit_interval(MPI.COMM_WORLD, 4)
    ctx = Context(fem.Function(fem.functionspace(msh, ("Lagrange", 1))))
    veto = Veto()
    with Problem(ctx, [Arctan(), veto], [], "bcfem_test_veto_") as problem:
        problem.state("x").x.array[:] = x0
        assert problem.solve()
        assert problem.inadmissible is None and problem.failure.startswith("SNES reason")
        # the same converged state, now vetoed: the solve fails, says why, and restores the start
        veto.message = "x = 0 vetoed"
        problem.state("x").x.array[:] = x0
        assert not problem.solve()
        assert problem.reason > 0  # SNES itself converged
        assert problem.failure == "converged to an inadmissible state: x = 0 vetoed"
        assert problem.state("x").x.array[0] == x0
        assert problem.rejections == 1 and problem.last_rejection == "x = 0 vetoed"


class Trust(Silent):
    """Allows only steps that keep x in [-1, 2] (as the self-contact allows only steps that
    keep the wall admissible)."""

    def step_bound(self, x, y):
        t = 1.0
        while t > 1e-3 and np.any(np.abs(x.array - t * y.array - 0.5) > 1.5):
            t *= 0.5
        return t


@pytest.mark.parametrize("bounded", [False, True])
def test_a_term_can_bound_the_newton_step(bounded):
    # full Newton on arctan from 2 overshoots ever further (the test above); shortened to
    # stay in [-1, 2], the first step lands near 0 and Newton converges
    msh = mesh.create_unit_interval(MPI.COMM_WORLD, 4)
    ctx = Context(fem.Function(fem.functionspace(msh, ("Lagrange", 1))))
    with Problem(ctx, [Arctan(), Trust()], [], "bcfem_test_step_bound_", {"snes_max_it": 40}) as problem:
        if bounded:
            problem.bound_steps()
        problem.state("x").x.array[:] = 2.0
        assert problem.solve() == bounded
        assert (problem.bounded_steps > 0) == bounded
        if bounded:
            assert abs(problem.state("x").x.array[0]) < 1e-10


@pytest.mark.parametrize("divtol", [None, -3.0])
def test_a_residual_grown_past_the_divergence_tolerance_stops_the_solve(divtol):
    """vinewtonrsls applies no divergence test: the residual callback does. A residual over
    snes_divergence_tolerance (PETSc's 1e4 unless the user sets it; PETSC_UNLIMITED, -3: off) times the
    solve's first is reported as NaN, so SNES stops rather than iterate to snes_max_it."""
    msh = mesh.create_unit_interval(MPI.COMM_WORLD, 4)
    ctx = Context(fem.Function(fem.functionspace(msh, ("Lagrange", 1))))
    options = {} if divtol is None else {"snes_divergence_tolerance": divtol}
    with Problem(ctx, [Arctan()], [], "bcfem_test_divergence_", options) as problem:
        assert problem.snes.getDivergenceTolerance() == (1e4 if divtol is None else divtol)
        f = problem.new_vector()
        problem._first_norm = None  # as at the start of a solve
        for value, grown in ((1e-6, False), (1e-3, False), (1.0, divtol is None)):
            problem.state("x").x.array[:] = value
            x = problem.vector_from(problem.states)
            problem.snes.computeFunction(x, f)
            # arctan(1) = 0.785 > 1e4 * arctan(1e-6); arctan(1e-3) is 1e3 times the first
            assert np.isnan(f.norm()) == grown


class Anharmonic(Term):
    """|u'|^2/2 + k u^4/4 - u (k a run-time constant, 1): a nonlinear bar, held at x = 0 by a
    Dirichlet condition."""

    def energy(self, ctx):
        u, k = ctx.u, ctx.constant("quartic", 1.0)
        return (0.5 * ufl.inner(ufl.grad(u), ufl.grad(u)) + 0.25 * k * u**4 - u) * ufl.dx


TIGHT = {"snes_rtol": 1e-14, "snes_atol": 1e-13}


def held_bar(terms, prefix):
    """(context, Dirichlet value g, its dofs, problem) of the bar held at x = 0."""
    msh = mesh.create_unit_interval(MPI.COMM_WORLD, 16)
    V = fem.functionspace(msh, ("Lagrange", 2))
    g = fem.Function(V)
    dofs = fem.locate_dofs_geometrical(V, lambda x: np.isclose(x[0], 0.0))
    ctx = Context(fem.Function(V))
    return ctx, g, dofs, Problem(ctx, terms, [fem.dirichletbc(g, dofs)], prefix, TIGHT)


def test_the_residual_is_lifted_only_where_x_is_off_its_dirichlet_values():
    # dolfinx's lifting adds J (g - x); bcfem skips it where g - x is round-off. Each solve
    # moves g, so its first residual needs it and no later one; the states equal a solve by
    # dolfinx's own residual (lifting at every evaluation).
    ctx, g, dofs, problem = held_bar([Anharmonic()], "bcfem_test_lift_")
    with problem:
        states = []
        for value in (0.3, 0.7, -0.2):
            g.x.array[:] = value
            assert problem.solve()
            states.append(ctx.u.x.array.copy())
        solves, iterations, liftings = 3, problem.newton_iterations, problem.assembly.liftings
    assert liftings == solves and iterations >= 2 * solves  # residuals: at least 2 per solve
    reference = fem.Function(ctx.u.function_space)
    residual = ufl.derivative(Anharmonic().energy(Context(reference)), reference)
    for value, state in zip((0.3, 0.7, -0.2), states):
        g.x.array[:] = value
        solver = NonlinearProblem(residual, reference, bcs=problem.bcs, petsc_options_prefix="bcfem_test_lift_ref_",
                                  petsc_options={"snes_type": "newtonls", "snes_linesearch_type": "basic",
                                                 "ksp_type": "preonly", "pc_type": "lu", **TIGHT})
        solver.solve()
        assert solver.solver.getConvergedReason() > 0
        np.testing.assert_allclose(state, reference.x.array, rtol=0, atol=1e-12)
        assert np.allclose(state[dofs], value, rtol=0, atol=1e-15)


def test_only_the_conditions_x_misses_lift_the_residual():
    """A bar held at both ends, the right end moved: the residual lifted by the right end alone
    is dolfinx's, lifted by both; the held end is left out of the lifting."""
    from dolfinx.fem.petsc import assemble_residual

    msh = mesh.create_unit_interval(MPI.COMM_WORLD, 16)
    V = fem.functionspace(msh, ("Lagrange", 2))
    held, moved = fem.Function(V), fem.Function(V)
    ends = [fem.dirichletbc(g, fem.locate_dofs_geometrical(V, lambda x, at=at: np.isclose(x[0], at)))
            for g, at in ((held, 0.0), (moved, 1.0))]
    ctx = Context(fem.Function(V))
    with Problem(ctx, [Anharmonic()], ends, "bcfem_test_lift_two_", TIGHT) as problem:
        x = problem.vector_from(problem.states)
        moved.x.array[:] = 0.4
        assert problem.assembly.unlifted.missed(x) == [ends[1]]
        ours, theirs = problem.new_vector(), problem.new_vector()
        problem.snes.computeFunction(x, ours)
        kargs = problem.assembly._kargs
        assemble_residual(problem.snes, x, theirs, kargs["u"], kargs["residual"], kargs["jacobian"], ends,
                          kargs["_blocks"])
        assert ours.norm() > 0.1
        theirs.axpy(-1.0, ours)
        assert theirs.norm() <= 1e-14 * ours.norm()
        assert problem.solve()
        x = problem.vector_from(problem.states)
        assert problem.assembly.unlifted.missed(x) == []
        assert problem.assembly.liftings == 2  # the one above and the solve's first residual


class SymmetricSilent(Silent):
    """A silent discrete term that declares its (zero) tangent symmetric, but no tangent key."""

    symmetric_tangent = True


def test_a_tangent_at_the_same_state_is_assembled_once():
    # a stability count assembles J at the converged state, and the next solve starts there:
    # its first Jacobian is that matrix. A discrete term without tangent_key turns the memo off;
    # a symmetric one keeps LDL^T, so that both solves take the same arithmetic, bit for bit.
    results = []
    for extra in ((), (SymmetricSilent(),)):
        ctx, g, _, problem = held_bar([Anharmonic(), *extra], "bcfem_test_memo_")
        with problem:
            for value in (0.3, 0.7, -0.2):
                g.x.array[:] = value
                assert problem.solve()
                problem.jacobian()  # as the stability count does
            results.append((ctx.u.x.array.copy(), problem.assembly.memo.reused, problem.newton_iterations))
    (u_memo, reused, its), (u_fresh, reused_fresh, its_fresh) = results
    # the 2nd and 3rd solves' first Jacobians, and the 1st's (assembled for MUMPS's memory estimate)
    assert reused == 3 and reused_fresh == 0
    assert its == its_fresh and np.array_equal(u_memo, u_fresh)


def test_a_changed_constant_makes_the_tangent_anew():
    ctx, g, _, problem = held_bar([Anharmonic()], "bcfem_test_memo_k_")
    with problem:
        g.x.array[:] = 0.5
        assert problem.solve()
        first = problem.jacobian()[0].copy()
        ctx.constant("quartic").value = 3.0
        reused = problem.assembly.memo.reused  # the first solve's: the memory estimate's tangent
        second = problem.jacobian()[0].copy()
        assert problem.assembly.memo.reused == reused
        again = problem.jacobian()[0]
        assert problem.assembly.memo.reused == reused + 1
        assert again.equal(second) and not second.equal(first)
        for A in (first, second):
            A.destroy()


def test_a_term_has_a_default_name_and_no_multipliers_and_a_stranger_is_refused():
    """The term contract is a type: a Term's defaults, and an object that is no Term refused at
    once with the fix, not found out by a probe deep in the solver."""
    assert Arctan().name == "Arctan" and Arctan().multipliers == ()

    class Stranger:
        def energy(self, ctx):
            return 0.5 * ctx.u**2 * ufl.dx

    msh = mesh.create_unit_interval(MPI.COMM_WORLD, 4)
    ctx = Context(fem.Function(fem.functionspace(msh, ("Lagrange", 1))))
    with pytest.raises(TypeError, match="Stranger is not an energy term: inherit bcfem.Term"):
        Problem(ctx, [Stranger()], [], "bcfem_test_stranger_")


class Spring1D(Term):
    """(1/2)∫u'² - ∫ f u with ∫ f = 0: without a Dirichlet condition u + c is as good as u."""

    def energy(self, ctx):
        x = ufl.SpatialCoordinate(ctx.mesh)[0]
        return (0.5 * ctx.u.dx(0) ** 2 - ufl.cos(2 * ufl.pi * x) * ctx.u) * ufl.dx


@pytest.mark.parametrize("held", [True, False])
def test_a_singular_tangent_is_reported(held):
    """A free rigid mode (here a constant shift) gives the tangent a null pivot: the problem
    counts it, the log says so and the run's summary reports it; held at one end, the
    tangent is regular."""
    from bcfem.run.runner import solve
    from bcfem.run.stages import Scene

    msh = mesh.create_unit_interval(MPI.COMM_WORLD, 8)
    V = fem.functionspace(msh, ("Lagrange", 2))
    ctx = Context(fem.Function(V))
    left = fem.locate_dofs_geometrical(V, lambda x: np.isclose(x[0], 0.0))
    bcs = [fem.dirichletbc(0.0, left, V)] if held else []

    class Toy(Scene):
        name, stages = "toy", ("solve",)

        def solve(self, run):
            with run.stage("solve", ctx, [Spring1D()], bcs) as problem:
                assert problem.solve()
                assert (problem.null_pivots == 0) == held

    _, summary = solve(Toy(), MPI.COMM_WORLD)
    assert (summary["null_pivots"] == 0) == held
