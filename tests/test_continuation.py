"""Arc-length continuation on toys whose paths, folds and events are known in closed form.

Each toy is an energy on the unit interval with a piecewise-constant (DG0)
"displacement": one cell gives one dof, and the reference mean of the norm is the
plain integral. The load is a real-space state whose row is the arc-length equation,
as in every bcfem scene. Marked ``mpi`` only where the run is on ``COMM_WORLD``.
"""

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

from mpi4py import MPI

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh

from bcfem import ArcLength, Context, ContinuationParams, Problem, Switch, Term, global_sum, real_value
from bcfem.kinematics.solid import AxisymmetricSolid

PARAMS = ContinuationParams(ds=0.05, ds_max=0.2, event_tol=1e-11)
#: the fold-location bar: limit points and events to 1e-10 in the state
LOCATED = 1e-10
#: Newton to round-off, so that what is measured is the continuation's error, not Newton's
#: (with bcfem's default snes_atol = 1e-10, Newton's error alone can reach 1e-10)
NEWTON = {"snes_atol": 1e-13, "snes_rtol": 1e-15}
#: every converged point has a residual below snes_atol, and the closed-form path checks
#: below are residual rows (or the sum of two)
CONVERGED = NEWTON["snes_atol"]
SQRT23 = math.sqrt(2 / 3)
_prefixes = itertools.count()


@dataclass(frozen=True)
class Energy(Term):
    """A toy energy term: ``density(ctx)`` per unit length of the unit interval."""

    density: Callable

    def energy(self, ctx):
        return self.density(ctx) * ufl.dx(domain=ctx.mesh)


def spring(w):
    """A softening-stiffening spring W(w) = w^4/4 - 3w^2/2: force w^3 - 3w, folds at w = -+1."""
    return w**4 / 4 - 1.5 * w**2


class Toy:
    """A context on the unit interval, the problem with the arc-length row, and observables.

    Args:
        density: the energy density, a function of the context.
        parameter: the load's state.
        guess: start values of the states (``parameter``'s is the load guess).
        real_states: real-space states to create before the continuation (e.g. for its norm).
        norm, params: as for :class:`ArcLength`.
        comm, cells: the mesh.
    """

    def __init__(self, density, parameter, guess, real_states=(), norm=None, params=PARAMS,
                 comm=MPI.COMM_SELF, cells=1):
        msh = mesh.create_unit_interval(comm, cells)
        self.ctx = Context(fem.Function(fem.functionspace(msh, ("DG", 0)), name="displacement"))
        for name in real_states:
            self.ctx.real_state(name)
        self.arc = ArcLength(self.ctx, parameter, params, norm=norm, mean=lambda f: f * ufl.dx(domain=msh))
        self.problem = Problem(self.ctx, [Energy(density)], [], f"toy_continuation_{next(_prefixes)}_",
                               NEWTON, rows=self.arc.rows())
        self._means = {name: fem.form(state * ufl.dx(domain=msh)) for name, state in self.ctx.states.items()}
        for name, value in guess.items():
            self.ctx.states[name].x.array[:] = value
        self.arc.start(self.problem, guess[parameter])

    def observe(self) -> dict:
        return {name: global_sum(form) for name, form in self._means.items()}

    def trace(self, end, grows: str, direction: int = 1, switches=()):
        """Trace until ``end(values)`` turns positive, first along the way that makes
        ``grows`` grow (``direction=-1``: the other way)."""
        forward = self.arc.forward_sign(self.problem, self.observe, grows)
        try:
            return self.arc.trace(self.problem, self.observe, end, direction=direction * forward,
                                  switches=switches)
        finally:
            self.problem.close()


def assert_limit_point(lp, kind, **expected):
    assert lp.kind == kind
    for key, value in expected.items():
        assert abs(lp.values[key] - value) < LOCATED, (key, lp.values[key] - value)


# -- a straight path ------------------------------------------------------------------------
def linear(ctx):
    """F(u, lambda) = u - lambda."""
    return ctx.u**2 / 2 - ctx.real_state("load") * ctx.u


@pytest.mark.parametrize("direction", [1, -1])
@pytest.mark.parametrize("ds", [0.02, 0.1, 0.3])
def test_linear_path_is_u_equals_lambda_in_steps_of_ds(ds, direction):
    """On the straight path u = lambda the pseudo-arc length is the arc length: every step
    moves by ds in (u, lambda), and the end lambda = +-1 is at s = sqrt(2) |+-1 - 0.1|."""
    toy = Toy(linear, "load", {"displacement": 0.1, "load": 0.0},
              params=ContinuationParams(ds=ds, ds_max=ds, event_tol=1e-11))
    end = float(direction)
    branch = toy.trace(lambda v: direction * (v["load"] - end), "displacement", direction)
    u, lam, s = branch.column("displacement"), branch.column("load"), branch.column("s")
    assert np.max(np.abs(u - lam)) < 1e-14
    assert u[0] == pytest.approx(0.1, abs=1e-15)
    assert lam[-1] == pytest.approx(end, abs=1e-12)
    length = math.sqrt(2) * abs(end - 0.1)
    assert s[-1] == pytest.approx(length, abs=1e-12)
    steps = np.hypot(np.diff(u), np.diff(lam))
    assert np.max(np.abs(steps[:-1] - ds)) < 1e-13  # all but the last, which ends at the end point
    assert 0 < steps[-1] <= ds + 1e-13
    assert len(branch.rows) == 1 + math.ceil(length / ds)
    assert branch.limit_points == [] and branch.failed_steps == 0


# -- a one-dof fold -------------------------------------------------------------------------
def fold(ctx):
    """F(u, lambda) = u^3 - 3u - lambda: lambda max 2 at u = -1, min -2 at u = 1."""
    return spring(ctx.u) - ctx.real_state("load") * ctx.u


def test_one_dof_fold_is_located_to_1e_10():
    toy = Toy(fold, "load", {"displacement": -2.0, "load": 0.0})
    branch = toy.trace(lambda v: v["displacement"] - 2.0, "displacement")
    u, lam = branch.column("displacement"), branch.column("load")
    assert np.max(np.abs(lam - (u**3 - 3 * u))) < CONVERGED  # the one residual row
    assert u[0] == pytest.approx(-2.0, abs=1e-14) and u[-1] == pytest.approx(2.0, abs=1e-12)
    maximum, minimum = branch.limit_points
    assert_limit_point(maximum, "max", displacement=-1.0, load=2.0)
    assert_limit_point(minimum, "min", displacement=1.0, load=-2.0)


def test_hold_gives_the_load_and_the_trace_goes_on_from_there():
    """``hold`` makes the row lambda = value: Newton finds the equilibrium at that load
    (u^3 - 3u = 1.5 near u = -2), and a trace from it still locates the fold."""
    toy = Toy(fold, "load", {"displacement": -2.0, "load": 0.0})
    toy.arc.hold(toy.problem, 1.5)
    toy.ctx.u.x.array[:] = -2.0
    assert toy.problem.solve()
    u, lam = toy.observe()["displacement"], toy.observe()["load"]
    assert lam == pytest.approx(1.5, abs=1e-14) and abs(u**3 - 3 * u - 1.5) < CONVERGED
    branch = toy.trace(lambda v: v["displacement"] - 0.0, "displacement")
    assert_limit_point(branch.limit_points[0], "max", displacement=-1.0, load=2.0)


def test_a_correction_longer_than_allowed_cuts_the_step_and_the_fold_stays_exact():
    """A corrected point farther from its predictor than max_correction x ds is rejected
    like a failed solve: with a tight bound the steps shrink near the fold's curvature, and
    the fold is located as without it."""
    params = ContinuationParams(ds=0.3, ds_max=0.3, max_correction=0.01)
    toy = Toy(fold, "load", {"displacement": -2.0, "load": 0.0}, params=params)
    branch = toy.trace(lambda v: v["displacement"] - 2.0, "displacement")
    assert toy.arc.jumps > 0 and branch.failed_steps >= toy.arc.jumps
    maximum, minimum = branch.limit_points
    assert_limit_point(maximum, "max", displacement=-1.0, load=2.0)
    assert_limit_point(minimum, "min", displacement=1.0, load=-2.0)


# -- a snap-back ----------------------------------------------------------------------------
def snap_back(ctx):
    r"""The spring in series with a unit linear one, loaded at their free end v:
    W(w) + (v - w)^2/2 - lambda v, so lambda = w^3 - 3w and v = w^3 - 2w.
    Along w the load folds at w = -+1 and the displacement at w = -+sqrt(2/3)."""
    w, v = ctx.real_state("internal"), ctx.u
    return spring(w) + (v - w) ** 2 / 2 - ctx.real_state("load") * v


def snap_back_branch(comm=MPI.COMM_SELF, cells=1):
    toy = Toy(snap_back, "load", {"displacement": -4.0, "internal": -2.0, "load": -2.0},
              real_states=["internal"], norm={"displacement": 1.0, "internal": 1.0}, comm=comm, cells=cells)
    branch = toy.trace(lambda v: v["internal"] - 2.0, "internal")
    v, w, lam = (branch.column(k) for k in ("displacement", "internal", "load"))
    # the w-row is W'(w) - (v - w); each of the n v-rows is (v - w - lambda)/n
    assert np.max(np.abs(v - (w**3 - 2 * w))) < CONVERGED
    assert np.max(np.abs(lam - (w**3 - 3 * w))) < (1 + math.sqrt(cells)) * CONVERGED
    maximum, minimum = branch.limit_points
    assert_limit_point(maximum, "max", internal=-1.0, displacement=1.0, load=2.0)
    assert_limit_point(minimum, "min", internal=1.0, displacement=-1.0, load=-2.0)
    return branch


def test_snap_back_under_load_control_passes_both_displacement_folds():
    """Load as the parameter: the load folds are located; the displacement turns back twice."""
    branch = snap_back_branch()
    v, w = branch.column("displacement"), branch.column("internal")
    # v rises, falls between the displacement folds (inside the load folds), and rises again:
    # each sampled extremum brackets the true one, w = -+sqrt(2/3)
    top, bottom = np.flatnonzero(np.diff(np.sign(np.diff(v)))) + 1
    assert w[top - 1] < -SQRT23 < w[top + 1] and w[bottom - 1] < SQRT23 < w[bottom + 1]
    assert 4 / 3 * SQRT23 - 0.02 < v[top] < 4 / 3 * SQRT23 + CONVERGED


@pytest.mark.mpi
def test_snap_back_is_the_same_on_every_rank_count():
    """Two cells per rank, whose displacements all equal v (the one dof of the serial toy),
    and the internal dof on the real element: the folds of the serial toy."""
    comm = MPI.COMM_WORLD
    branch = snap_back_branch(comm, cells=2 * comm.size)
    serial = snap_back_branch()
    for a, b in zip(branch.limit_points, serial.limit_points):
        for key in ("displacement", "internal", "load"):
            assert a.values[key] == pytest.approx(b.values[key], abs=1e-12)


def displacement_control(ctx):
    """The same springs with v held to the platen position by a multiplier (the force):
    W(w) + (v - w)^2/2 - f (v - delta). The parameter delta folds where v does."""
    w, v, f = ctx.real_state("internal"), ctx.u, ctx.real_state("force")
    return spring(w) + (v - w) ** 2 / 2 - f * (v - ctx.real_state("platen"))


def test_snap_back_under_displacement_control_locates_the_displacement_folds():
    """The platen position as the parameter, the norm on the internal dof alone: the
    snap-back's folds are located; the force turns back at the load folds."""
    toy = Toy(displacement_control, "platen",
              {"displacement": -4.0, "internal": -2.0, "force": -2.0, "platen": -4.0},
              real_states=["internal", "force"], norm={"internal": 1.0})
    branch = toy.trace(lambda v: v["internal"] - 2.0, "internal")
    w, f = branch.column("internal"), branch.column("force")
    assert np.max(np.abs(branch.column("platen") - (w**3 - 2 * w))) < 2 * CONVERGED
    assert np.max(np.abs(f - (w**3 - 3 * w))) < 2 * CONVERGED
    maximum, minimum = branch.limit_points
    assert_limit_point(maximum, "max", internal=-SQRT23, platen=4 / 3 * SQRT23, force=7 / 3 * SQRT23)
    assert_limit_point(minimum, "min", internal=SQRT23, platen=-4 / 3 * SQRT23, force=-7 / 3 * SQRT23)
    assert len(np.flatnonzero(np.diff(np.sign(np.diff(f))))) == 2


# -- a switch -------------------------------------------------------------------------------
def test_switch_is_located_and_the_path_goes_on_with_the_new_model():
    """On the fold's falling part, at u = -1/2, a spring of stiffness 6 engages:
    lambda = u^3 - 3u before, u^3 + 3u + 3 after (no second fold). The path must turn
    at the switch to keep u growing (``grows``)."""

    def density(ctx):
        engaged = ctx.constant("engaged", 0.0)
        return fold(ctx) + engaged * 3 * (ctx.u + 0.5) ** 2

    toy = Toy(density, "load", {"displacement": -2.0, "load": 0.0})

    def engage():
        toy.ctx.constant("engaged").value = 1.0

    switch = Switch("engage", lambda v: v["displacement"] + 0.5, engage, grows="displacement")
    branch = toy.trace(lambda v: v["displacement"] - 1.0, "displacement", switches=[switch])
    (event,) = branch.events
    assert event["name"] == "engage"
    assert abs(event["displacement"] + 0.5) < LOCATED
    assert abs(event["load"] - 1.375) < LOCATED
    (maximum,) = branch.limit_points
    assert_limit_point(maximum, "max", displacement=-1.0, load=2.0)
    u, lam, s = branch.column("displacement"), branch.column("load"), branch.column("s")
    before, after = s < event["s"], s > event["s"]
    assert np.max(np.abs(lam[before] - (u[before] ** 3 - 3 * u[before]))) < CONVERGED
    assert np.max(np.abs(lam[after] - (u[after] ** 3 + 3 * u[after] + 3))) < CONVERGED
    assert np.all(np.diff(u[after]) > 0) and lam[-1] == pytest.approx(7.0, abs=1e-11)


# -- the solid's default norm ---------------------------------------------------------------
@dataclass(frozen=True)
class Tether(Term):
    """(1/2) int |u - lambda e_z|^2 dV: the body follows the rigid lift lambda e_z."""

    def energy(self, ctx):
        d = ctx.u - ctx.real_state("lift") * ufl.as_vector([0.0, 1.0])
        return ctx.kin.integral(0.5 * ufl.inner(d, d))


def test_solid_default_norm_is_the_reference_volume_mean():
    """On the unit square (r, z) in [0, 1]^2, V = pi; a uniform u = lambda e_z then has
    ||(du, dlambda)|| = sqrt(2) |dlambda| in the default norm (1/V) int |u|^2 dV + lambda^2."""
    msh = mesh.create_unit_square(MPI.COMM_SELF, 2, 2)
    u = fem.Function(fem.functionspace(msh, ("Lagrange", 1, (2,))), name="displacement")
    ctx = Context(u, AxisymmetricSolid(u, quadrature_degree=4))
    arc = ArcLength(ctx, "lift", ContinuationParams(ds=0.2, ds_max=0.2), 1.0)  # as runner.trace builds it
    assert ctx.kin.reference_volume == pytest.approx(math.pi, rel=1e-14)
    with Problem(ctx, [Tether()], [], f"toy_continuation_{next(_prefixes)}_", rows=arc.rows()) as problem:
        u.x.array[1::2] = 0.1
        arc.start(problem, 0.0)
        uz, ur = fem.form(ctx.kin.mean(u[1])), fem.form(ctx.kin.mean(u[0] ** 2))

        def observe():
            return {"uz": global_sum(uz), "ur2": global_sum(ur), "lift": real_value(ctx.states["lift"])}

        branch = arc.trace(problem, observe, lambda v: v["lift"] - 1.0)
    assert np.max(np.abs(branch.column("uz") - branch.column("lift"))) < 1e-13
    assert np.max(branch.column("ur2")) < 1e-26
    assert branch.rows[-1]["s"] == pytest.approx(math.sqrt(2) * 0.9, abs=1e-12)
    assert len(branch.rows) == 1 + math.ceil(math.sqrt(2) * 0.9 / 0.2)


def test_norm_is_declared_and_checked():
    msh = mesh.create_unit_interval(MPI.COMM_SELF, 1)
    ctx = Context(fem.Function(fem.functionspace(msh, ("DG", 0))))
    with pytest.raises(ValueError, match="no mean"):
        ArcLength(ctx, "load")
    mean = lambda f: f * ufl.dx(domain=msh)  # noqa: E731
    with pytest.raises(ValueError, match="does not hold"):
        ArcLength(ctx, "load", norm={"internal": 1.0}, mean=mean)
    with pytest.raises(ValueError, match="other than 'load'"):
        ArcLength(ctx, "load", norm={"load": 1.0}, mean=mean)
    with pytest.raises(ValueError, match="scales must be > 0"):
        ArcLength(ctx, "load", norm={"displacement": 0.0}, mean=mean)
