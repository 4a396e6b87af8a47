"""The parametric crater geometry: exact crater volume, named groups, clear errors."""

import math
import subprocess
import sys

from mpi4py import MPI

import pytest
import ufl
from dolfinx import fem

from bcfem.geometry.crater import AXIS, BOTTOM, CRATER, LAYER, OUTER, SPECIMEN, TOP, CraterGeometry, create_mesh

pytestmark = pytest.mark.mpi


def crater_volume(data) -> float:
    """V = -int 2 pi r z n_z over the crater surface (n: out of the solid); the plate adds nothing."""
    x = ufl.SpatialCoordinate(data.mesh)
    n = ufl.FacetNormal(data.mesh)
    ds = ufl.Measure("ds", domain=data.mesh, subdomain_data=data.facet_tags)
    form = fem.form(-2 * math.pi * x[0] * x[1] * n[1] * ds(CRATER))
    return data.mesh.comm.allreduce(fem.assemble_scalar(form), op=MPI.SUM)


@pytest.mark.parametrize("alpha, layer", [(1.0, 0.0), (0.5, 0.0), (0.7, 0.3)])
def test_crater_volume_is_exact_at_rest(alpha, layer):
    geometry = CraterGeometry(alpha=alpha, layer_thickness=layer)
    data = create_mesh(geometry, MPI.COMM_WORLD)
    # second-order geometry: only the quadratic interpolation of the arc remains, ~1e-7
    assert crater_volume(data) == pytest.approx(geometry.crater_volume, rel=2e-7)
    if alpha == 1.0:
        assert geometry.crater_volume == pytest.approx(2 * math.pi * 6.35**3 / 3, rel=1e-14)
    found = set(MPI.COMM_WORLD.allreduce(set(data.facet_tags.values.tolist()), op=MPI.BOR))
    assert {BOTTOM, CRATER, TOP, AXIS, OUTER} <= found
    regions = set(MPI.COMM_WORLD.allreduce(set(data.cell_tags.values.tolist()), op=MPI.BOR))
    assert regions == ({SPECIMEN, LAYER} if layer else {SPECIMEN})


def test_volume_converges_with_the_mesh():
    errors = [abs(crater_volume(create_mesh(CraterGeometry(size_crater=h, size_far=max(h, 0.5)),
                                            MPI.COMM_WORLD)) / CraterGeometry().crater_volume - 1)
              for h in (0.12, 0.06)]
    assert errors[1] < errors[0] / 8  # O(h^4) for quadratic arcs; at least third order seen


@pytest.mark.parametrize("alpha, layer", [(1.0, 0.0), (0.4, 0.0), (1.0, 0.3175)])
def test_quadrilateral_meshes_have_only_quadrilaterals_and_chords_of_order_h2(alpha, layer):
    """Q1-P0's meshes (--element q1p0): every cell a quadrilateral, also for a lining and a
    shallow cap, where gmsh's recombination alone left triangles; the straight-sided wall's
    chords fall short of the cap by their sag, h^2 / (12 rho^2) of the volume per unit area:
    halving h divides the shortfall by 4, give or take the rounding of the number of chords on
    the arc (2.8 on the shallow cap's 12 and 20 chords), and by more than first order's 2 in any case."""
    from dolfinx.mesh import CellType

    shortfalls = []
    for h in (0.12, 0.06):
        geometry = CraterGeometry(alpha=alpha, layer_thickness=layer, size_crater=h, order=1, cell="quadrilateral")
        data = create_mesh(geometry, MPI.COMM_WORLD)
        assert data.mesh.topology.cell_type == CellType.quadrilateral
        shortfalls.append(1 - crater_volume(data) / geometry.crater_volume)
    assert shortfalls[1] > 0 and 2.5 < shortfalls[0] / shortfalls[1] < 5.5, shortfalls


@pytest.mark.parametrize("kwargs, word", [
    ({"alpha": 1.2}, "alpha"),
    ({"alpha": 0.0}, "alpha"),
    ({"crater_radius": 12.7}, "crater radius"),
    ({"crater_radius": 13.0}, "crater radius"),
    ({"layer_thickness": 3.2}, "layer thickness"),
])
def test_bad_geometry_is_refused_before_meshing(kwargs, word):
    with pytest.raises(ValueError, match=word):
        CraterGeometry(**kwargs)


@pytest.mark.serial
def test_geometry_cli_writes_mesh_and_preview(tmp_path):
    out = tmp_path / "c.msh"
    res = subprocess.run([sys.executable, "-m", "bcfem.geometry", "crater", "--alpha", "0.7", "-o", str(out)],
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert out.stat().st_size > 1000 and out.with_suffix(".png").stat().st_size > 1000
    res = subprocess.run([sys.executable, "-m", "bcfem.geometry", "crater", "--alpha", "1.5", "-o",
                          str(tmp_path / "bad.msh")], capture_output=True, text=True, timeout=300)
    assert res.returncode == 2 and "alpha" in res.stderr and not (tmp_path / "bad.msh").exists()


@pytest.mark.parametrize("stretch_r, stretch_z", [(1.0, 1.0), (1.1, 0.8), (0.9, 1.05)])
def test_current_cavity_volume_under_an_affine_map(stretch_r, stretch_z):
    """Nanson's formula on the crater wall: an affine map scales the cavity by lr^2 lz."""
    import numpy as np

    from bcfem.kinematics.solid import AxisymmetricSolid
    from bcfem.physics.cavity import Cavity

    geometry = CraterGeometry(alpha=0.7)
    data = create_mesh(geometry, MPI.COMM_WORLD)
    V = fem.functionspace(data.mesh, ("Lagrange", 2, (2,)))
    u = fem.Function(V)
    u.interpolate(lambda x: np.vstack([(stretch_r - 1) * x[0], (stretch_z - 1) * x[1]]))
    kin = AxisymmetricSolid(u, quadrature_degree=4, facet_tags=data.facet_tags)
    volume = data.mesh.comm.allreduce(fem.assemble_scalar(fem.form(Cavity(CRATER).volume(kin))), op=MPI.SUM)
    assert volume == pytest.approx(geometry.crater_volume * stretch_r**2 * stretch_z, rel=2e-7)


@pytest.mark.parametrize("alpha, stretch", [(1.0, 1.0), (0.7, 1.0), (0.7, 1.1)])
def test_wall_surface_energy_is_gamma_times_current_area(alpha, stretch):
    """SolidSurfaceEnergy on the crater wall: gamma pi (a^2 + b^2) for a spherical cap,
    scaled by stretch^2 under a uniform dilation."""
    import numpy as np

    from bcfem.kinematics.solid import AxisymmetricSolid
    from bcfem.physics.context import Context
    from bcfem.physics.energies import SolidSurfaceEnergy

    geometry = CraterGeometry(alpha=alpha)
    data = create_mesh(geometry, MPI.COMM_WORLD)
    V = fem.functionspace(data.mesh, ("Lagrange", 2, (2,)))
    u = fem.Function(V)
    u.interpolate(lambda x: np.vstack([(stretch - 1) * x[0], (stretch - 1) * x[1]]))
    ctx = Context(u, AxisymmetricSolid(u, quadrature_degree=4, facet_tags=data.facet_tags))
    gamma = 0.37
    energy = data.mesh.comm.allreduce(fem.assemble_scalar(fem.form(
        SolidSurfaceEnergy(gamma, CRATER).energy(ctx))), op=MPI.SUM)
    a = geometry.crater_radius
    b = alpha * a
    assert energy == pytest.approx(gamma * math.pi * (a**2 + b**2) * stretch**2, rel=1e-6)
