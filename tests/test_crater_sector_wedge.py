"""The wedge pi/m of the crater's specimen (m = 3 and 8: the face theta = pi/m is no coordinate
plane, and u.n = 0 on it is a multiplier field, :class:`bcfem.scenes.crater_sector.model.MirrorPlane`).

Its mesh is the wedge's share of the specimen, and its cycle equals the axisymmetric crater's
where nothing breaks the symmetry, to the quarter's discretisation error on the same element
sizes (tests/test_crater_sector.py: 3.4e-5 in V/V0, 3.0e-4 in A2/A0, 2.1e-6 in p on the coarse
mesh); on 2 ranks it equals COMM_SELF's.
"""

import math

from mpi4py import MPI

import pytest
import ufl
from dolfinx import fem

from bcfem.geometry.crater_sector import MIRROR_END, MIRROR_START, WALL, CraterSector, create_mesh
from bcfem.scenes import crater
from bcfem.scenes.crater_sector import cycle

PRELOAD = 0.02


@pytest.mark.mpi
@pytest.mark.parametrize("m", [3, 8])
def test_the_wedge_is_its_share_of_the_specimen(m):
    wedge = CraterSector(wedge_waves=m)
    data = create_mesh(wedge, MPI.COMM_WORLD)
    msh = data.mesh
    ds = ufl.Measure("ds", msh, subdomain_data=data.facet_tags)

    def total(form):
        return msh.comm.allreduce(fem.assemble_scalar(fem.form(form)))

    a, R, H = wedge.crater_radius, wedge.radius, wedge.height
    assert total(1 * ufl.dx(msh)) == pytest.approx((math.pi * R**2 * H - 2 * math.pi * a**3 / 3) / (2 * m), rel=1e-4)
    assert total(1 * ds(WALL)) == pytest.approx(math.pi * a**2 / m, rel=1e-4)
    for face in (MIRROR_START, MIRROR_END):  # a rectangle R x H less a quarter disc of the crater
        assert total(1 * ds(face)) == pytest.approx(R * H - math.pi * a**2 / 4, rel=1e-4)


@pytest.mark.slow
@pytest.mark.mpi
def test_the_wedge_cycle_equals_the_axisymmetric_crater():
    comm = MPI.COMM_WORLD
    axi_rows, _ = crater.solve(crater.Params(preload=PRELOAD, surface_energy=0.0, self_contact=0.0), comm)
    loaded = next(r for r in axi_rows if r["stage"] == "load" and r["eps"] == PRELOAD)
    unloaded = axi_rows[-1]  # at zero platen force, eps ~ 1e-4; p'(eps) ~ 0.26 there
    quarter = cycle(PRELOAD, steps=1, comm=comm)
    for m in (3, 8):
        rows = cycle(PRELOAD, steps=1, sector=CraterSector(wedge_waves=m), comm=comm)
        assert rows[0]["V_over_V0"] == pytest.approx(loaded["V_over_V0"], abs=1e-4)
        assert rows[0]["A_over_A0"] == pytest.approx(loaded["A_over_A0"], abs=5e-4)
        assert rows[1]["p_over_pa"] == pytest.approx(quarter[1]["p_over_pa"], abs=1e-5)
        assert rows[1]["p_over_pa"] == pytest.approx(unloaded["p_over_pa"], abs=5e-5)
        if comm.size > 1:
            serial = cycle(PRELOAD, steps=1, sector=CraterSector(wedge_waves=m), comm=MPI.COMM_SELF)
            for row, alone in zip(rows, serial):
                for key in ("V_over_V0", "A_over_A0", "p_over_pa"):
                    assert row[key] == pytest.approx(alone[key], abs=1e-9)
