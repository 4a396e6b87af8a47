"""The 3-D quarter of the crater with a stiff lining, and its first non-axisymmetric bifurcation.

* the lined quarter's mesh: the lining's volume and the wall's and the interface's areas equal a
  quarter of the spherical shell's (quadratic geometry: to 1e-4);
* (study, minutes) pulled by a dead suction at eps = 0, the quarter loses stability, by the
  inertia of its 3-D tangent, within 5 % of the suction where the axisymmetric scene's n-wave
  check first finds an n-block the quarter admits (n even) unstable.
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


@pytest.mark.study
def test_the_quarters_first_bifurcation_is_the_axisymmetric_n_wave_onset():
    """(study: about 6 minutes on 2 cores.) A lining t = 0.05 a, beta' = 1000, its crater's volume
    drawn off at eps = 0: the quarter (size 0.1 a) first has unstable modes, by the inertia of its
    3-D tangent, within 5 % in suction of where the axisymmetric crater (size 0.05 a) first has an
    even-n block unstable (n = 8 there), with no axisymmetric mode unstable: the quarter's
    bifurcation breaks the symmetry."""
    import numpy as np

    from bcfem.scenes.crater_sector import axisymmetric_suction_waves, drawn_stability

    sector = CraterSector(size_wall=0.1, size_far=0.6, layer_thickness=0.05)
    removed = [0.01, 0.02, 0.03, 0.034, 0.036, 0.037, 0.038, 0.0385, 0.039, 0.04]
    quarter = drawn_stability(removed, layer_stiffness=1000, sector=sector, bisections=3)
    stable = max(s for _, count, s in quarter["rows"] if count == 0)
    unstable = min((s for _, count, s in quarter["rows"] if count > 0), default=None)
    assert unstable is not None, quarter
    axi = axisymmetric_suction_waves(np.arange(0.03, 0.045, 0.00025), 16, 0.05, 1000, 0.05, drawn=True)
    first = next(r for r in axi if any(c > r["n0"] for n, c in r["waves"].items() if n % 2 == 0))
    print("quarter: stable to s =", stable, "unstable from", unstable, "; axisymmetric: even n from s =",
          first["s"], first["waves"])
    assert all(r["n0"] == 0 for r in axi if r["s"] <= unstable)
    assert stable < unstable and abs(unstable / first["s"] - 1) < 0.05
