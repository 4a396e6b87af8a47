"""Observables and the columns they fill: each shared observable against a closed form,
serial and on 2 ranks (marker ``mpi``: every rank gets the same value), and every scene's
declared columns, their units and the ``--help`` that lists them."""

import math

from mpi4py import MPI

import numpy as np
import pytest
from dolfinx import fem, mesh

from bcfem import AxisymmetricMembrane, Context
from bcfem.columns import SHARED, Column, declare, help_text, names, record, union
from bcfem.physics.observables import Integral, Measured, RealState, cavity_volume, pressure, row
from bcfem.scenes import REGISTRY


def cone(h: float, comm=MPI.COMM_WORLD) -> Context:
    """The membrane lifted to a cone of height h over the unit disc, z = h (1 - R): volume π h / 3
    (P2 holds it exactly)."""
    msh = mesh.create_interval(comm, 8, [0.0, 1.0])
    u = fem.Function(fem.functionspace(msh, ("Lagrange", 2, (2,))))
    u.interpolate(lambda x: np.vstack([0 * x[0], h * (1 - x[0])]))
    return Context(u, AxisymmetricMembrane(u, quadrature_degree=6))


@pytest.mark.mpi
def test_the_shared_observables_against_closed_forms():
    h = 0.6
    ctx = cone(h)
    kin = ctx.kin
    V0 = 4 * math.pi / 3
    volume = cavity_volume(kin.integral(kin.volume_density), V0)
    state = ctx.real_state("pressure")
    state.x.array[:] = 2.5
    area = Integral.of(Column("area", "pi R0^2", "the membrane's current area"), kin.integral(kin.area_stretch),
                       math.pi)
    values = row([volume, pressure(state), area, Measured(SHARED["aspect"], lambda: h)])
    assert list(values) == ["V_over_V0", "P", "area", "aspect"]
    assert values["V_over_V0"] == pytest.approx(h / 4, rel=1e-12)  # (π h / 3) / (4 π / 3)
    assert values["P"] == 2.5 and values["aspect"] == h
    assert values["area"] == pytest.approx(math.sqrt(1 + h**2), rel=1e-12)  # the cone's lateral area over π
    # every rank holds the same numbers (a collective sum, not a rank's share)
    assert MPI.COMM_WORLD.allgather(values["V_over_V0"]) == [values["V_over_V0"]] * MPI.COMM_WORLD.size


def test_a_real_state_and_a_scale():
    ctx = cone(0.1, MPI.COMM_SELF)
    state = ctx.real_state("debond_radius")
    state.x.array[:] = 3.0
    assert RealState(SHARED["R1_over_R0"], state, scale=2.0).value() == 1.5


def test_declared_columns():
    own = Column("F_hat", "mu A0", "suction force over mu A0")
    columns = declare("stage", "eps", own)
    assert names(columns) == ["stage", "eps", "F_hat"] and columns[0] is SHARED["stage"]
    assert record(columns)[2] == {"name": "F_hat", "unit": "mu A0", "meaning": "suction force over mu A0"}
    with pytest.raises(ValueError, match="twice"):
        declare("eps", "eps")
    with pytest.raises(KeyError):
        declare("no_such_column")
    assert names(union(columns, declare("eps", "s"))) == ["stage", "eps", "F_hat", "s"]


@pytest.mark.parametrize("scene", list(REGISTRY))
def test_every_column_of_a_scene_is_declared_with_a_unit_and_listed_by_help(scene):
    columns = REGISTRY[scene].COLUMNS
    assert all(isinstance(c, Column) and c.meaning and isinstance(c.unit, str) for c in columns)
    assert len(set(names(columns))) == len(columns)
    text = help_text(columns)
    for c in columns:
        assert c.line() in text
