"""One set of term objects on two kinematics: an axisymmetric cylinder and a 3-D quarter of it.

The same ``SolidStrain`` (nearly incompressible neo-Hookean, mixed pressure),
``SolidSurfaceEnergy`` and ``IdealGas`` (its cavity closed by the plate) terms are evaluated on
``AxisymmetricSolid`` over the half cross-section and on ``Solid3D`` over a quarter of the
cylinder, for the same displacement and pressure. Four quarters must give the axisymmetric
values, to the geometry's discretisation error (the quarter's curved face is quadratic).
"""

import math

from mpi4py import MPI

import numpy as np
import pytest
from dolfinx import fem, mesh

from bcfem.kinematics.solid import AxisymmetricSolid
from bcfem.kinematics.solid_3d import Solid3D
from bcfem.mpi import global_sum
from bcfem.physics.cavity import Cavity
from bcfem.physics.context import Context
from bcfem.physics.energies import SolidStrain, SolidSurfaceEnergy
from bcfem.physics.fluids import IdealGas
from bcfem.physics.materials import NearlyIncompressibleNeoHookean

pytestmark = pytest.mark.mpi  # equal on 2 ranks: the sums go through global_sum

A, B, C, D = 0.1, -0.2, -0.15, 0.05  # u_r = (A + B z) r, u_z = C z + D r^2
SIDE, AXIS = 7, 9  # facet tags of the cylinder's curved face r = 1 and of the axis
TERMS = [SolidStrain(NearlyIncompressibleNeoHookean(mu=1.0, kappa=50.0)), SolidSurfaceEnergy(0.3, SIDE)]


def axisymmetric():
    msh = mesh.create_rectangle(MPI.COMM_WORLD, [[0, 0], [1, 1]], [16, 16])
    msh.topology.create_connectivity(1, 2)
    facets = mesh.exterior_facet_indices(msh.topology)
    midpoints = mesh.compute_midpoints(msh, 1, facets)
    # the axis (tag AXIS) has no area, and its quadrature points sit where u_r/r is 0/0
    marks = np.select([np.isclose(midpoints[:, 0], 1.0), np.isclose(midpoints[:, 0], 0.0)], [SIDE, AXIS], 8)
    marks = marks.astype(np.int32)
    order = np.argsort(facets)
    tags = mesh.meshtags(msh, 1, facets[order], marks[order])
    u = fem.Function(fem.functionspace(msh, ("Lagrange", 2, (2,))))
    u.interpolate(lambda x: [(A + B * x[1]) * x[0], C * x[1] + D * x[0] ** 2])
    ctx = Context(u)
    ctx.kin = AxisymmetricSolid(u, quadrature_degree=6, facet_tags=tags)
    ctx.facet_tags = tags
    return ctx, lambda x: 0.1 + 0.2 * x[1]


def quarter():
    """A quarter of the unit cylinder, quadratic tetrahedra (gmsh)."""
    import gmsh

    from bcfem.geometry.mesh import distribute

    def build():
        occ = gmsh.model.occ
        cylinder = occ.addCylinder(0, 0, 0, 0, 0, 1, 1.0)
        box = occ.addBox(0, 0, 0, 2, 2, 1)
        occ.intersect([(3, cylinder)], [(3, box)])
        occ.synchronize()
        volumes = gmsh.model.getEntities(3)
        gmsh.model.addPhysicalGroup(3, [t for _, t in volumes], 1)
        for _, tag in gmsh.model.getEntities(2):
            x, y, z = gmsh.model.occ.getCenterOfMass(2, tag)
            side = np.hypot(x, y) > 0.5 and 0.2 < z < 0.8 and x > 0.05 and y > 0.05
            gmsh.model.addPhysicalGroup(2, [tag], SIDE if side else 100 + tag)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.15)
        gmsh.model.mesh.generate(3)
        gmsh.model.mesh.setOrder(2)

    data = distribute(build, MPI.COMM_WORLD, gdim=3)
    u = fem.Function(fem.functionspace(data.mesh, ("Lagrange", 2, (3,))))
    u.interpolate(lambda x: [(A + B * x[2]) * x[0], (A + B * x[2]) * x[1], C * x[2] + D * (x[0] ** 2 + x[1] ** 2)])
    ctx = Context(u)
    ctx.kin = Solid3D(u, quadrature_degree=6, facet_tags=data.facet_tags)
    ctx.facet_tags = data.facet_tags
    return ctx, lambda x: 0.1 + 0.2 * x[2]


def values(ctx, pressure, parts: int = 1) -> dict:
    """The terms' energies; the gas is sealed in 1/parts of the axisymmetric body's volume
    (each of ``parts`` pieces holds its share)."""
    kin = ctx.kin
    ranks = ctx.mesh.comm.allgather(set(ctx.facet_tags.values.tolist()))
    boundary = tuple(sorted({int(t) for part in ranks for t in part} - {AXIS}))
    gas = IdealGas(Cavity(boundary), sealed_volume=2.0 / parts)
    out = {}
    for term in [*TERMS, gas]:
        form = term.energy(ctx)
        if "solid_pressure" in ctx.states:
            ctx.states["solid_pressure"].interpolate(pressure)
        if "fluid_pressure" in ctx.states:
            ctx.states["fluid_pressure"].x.array[:] = 1.3
        out[term.name] = global_sum(fem.form(form))
    # the body seen as the cavity's complement: the plate-closed volume of its own surface
    out["plate_closed_volume"] = -global_sum(fem.form(Cavity(boundary).volume(kin)))
    out["current_volume"] = global_sum(fem.form(kin.integral(kin.J)))
    return out


@pytest.mark.parametrize("name", ["solid_strain", "gamma_solid", "ideal_gas", "current_volume"])
def test_four_quarters_are_the_axisymmetric_body(name):
    axi, quarters = values(*axisymmetric()), values(*quarter(), parts=4)
    assert 4 * quarters[name] == pytest.approx(axi[name], rel=2e-4)


def test_volume_by_the_plate_closed_surface_is_the_body_volume():
    """The divergence theorem with (0, 0, z) through Nanson's formula: the same functional in both."""
    for ctx, _ in (axisymmetric(), quarter()):
        found = values(ctx, lambda x: 0 * x[0])
        assert found["plate_closed_volume"] == pytest.approx(found["current_volume"], rel=1e-6)
        assert math.isfinite(found["plate_closed_volume"])
