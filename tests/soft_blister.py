"""A small blister on a soft substrate and its Taylor battery, shared by the blister-soft tests."""

from mpi4py import MPI

import numpy as np
import pytest
from dolfinx import fem
from helpers import assert_second_order, taylor

from bcfem import global_sum
from bcfem.scenes import blister_soft
from bcfem.solver.problem import Problem

L = 2.0


SMALL = dict(size_factor=L, size_contact=0.05, growth=1.5, stiffness_ratio=3.0, alpha=0.7, gamma_ls=0.4,
             delta_gamma=0.3, kappa_ratio=50.0)


def small_model(comm=MPI.COMM_WORLD):
    from bcfem.scenes.blister_soft.model import Model

    return Model(blister_soft.Params(**SMALL), comm)


def W(lam):
    """The incompressible neo-Hookean membrane at an equibiaxial stretch (mu t0 = 1)."""
    return 0.5 * (2 * lam**2 + lam**-4 - 3)


def direction(problem, extra=None):
    """A smooth direction, 0 on every Dirichlet dof (the same on any partition); ``extra``:
    values of real states."""
    fields = {n: fem.Function(s.function_space) for n, s in zip(problem.names, problem.states)}
    for name, value in (extra or {}).items():
        fields[name].x.array[:] = value
    fields["displacement"].interpolate(lambda x: np.vstack([x[0] * np.sin(3 * x[1]), np.cos(2 * x[0]) * (x[1] + L)]))
    fields["lift"].interpolate(lambda x: np.vstack([x[0] * (1 - x[0]), 1 - x[0] ** 2]))
    fields["solid_pressure"].interpolate(lambda x: np.cos(x[0] + x[1]))
    fields["pressure"].x.array[:] = 1.0
    for name, f in fields.items():
        f.x.array[problem.constrained(name)] = 0.0
    return problem.vector_from(fields.values())


def taylor_of(model, prefix: str, extra=None):
    """The standard battery's Taylor remainders (tests/test_terms.py) of every term of
    ``model`` together, at its current states, along a smooth direction (``extra``: the
    direction's values of real states)."""
    problem = Problem(model.ctx, model.terms, model.bcs, prefix, rows=getattr(model, "rows", None))
    energy = fem.form(problem.lagrangian, entity_maps=model.ctx.entity_maps)
    d = direction(problem, extra)
    result = taylor(problem, lambda: global_sum(energy), d, eps0=5e-3, halvings=5)
    d.destroy()
    problem.close()
    return result


def assert_battery(at, comm=MPI.COMM_WORLD):
    """Second-order remainders of ``at(comm)``; on 2 ranks the numbers of ``at(COMM_SELF)``."""
    result = at(comm)
    assert_second_order(result, tol=0.1)
    if comm.size > 1:
        serial = at(MPI.COMM_SELF)
        assert result["energy"] == pytest.approx(serial["energy"], rel=1e-12)
        for key in ("energy_remainders", "residual_remainders"):
            assert result[key] == pytest.approx(serial[key], rel=1e-6)
