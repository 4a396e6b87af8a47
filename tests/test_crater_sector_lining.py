"""The 3-D quarter of the crater with a stiff lining.

The lined quarter's mesh: the lining's volume and the wall's and the interface's areas equal a
quarter of the spherical shell's (quadratic geometry: to 1e-4). Its onset against the axisymmetric
n-wave check is in docs/three-dimensional.md (a script's numbers: the serial path is not yet robust
at the singular point, so it is no test yet).
"""

import math

from mpi4py import MPI

import pytest
import ufl
from dolfinx import fem

from bcfem.geometry.crater_sector import INTERFACE, LAYER, WALL, CraterSector, create_mesh

LINED = CraterSector(size_wall=0.25, size_far=0.6, layer_thickness=0.05)


@pytest.mark.mpi
def test_the_lined_quarter_is_a_quarter_of_the_shell():
    data = create_mesh(LINED, MPI.COMM_WORLD)
    msh = data.mesh
    dx = ufl.Measure("dx", msh, subdomain_data=data.cell_tags)
    ds = ufl.Measure("ds", msh, subdomain_data=data.facet_tags)
    dS = ufl.Measure("dS", msh, subdomain_data=data.facet_tags)

    def total(form):
        return msh.comm.allreduce(fem.assemble_scalar(fem.form(form)))

    a, b = LINED.crater_radius, LINED.crater_radius * (1 + LINED.layer_thickness)
    assert total(1 * dx(LAYER)) == pytest.approx(math.pi * (b**3 - a**3) / 6, rel=1e-4)
    assert total(1 * ds(WALL)) == pytest.approx(math.pi * a**2 / 2, rel=1e-4)
    assert total(1 * dS(INTERFACE)) == pytest.approx(math.pi * b**2 / 2, rel=1e-4)

