"""The soft substrate geometry: exact measures, the contact vertex, the grading and clear errors."""

import math
import subprocess
import sys

from mpi4py import MPI

import numpy as np
import pytest
import ufl
from dolfinx import fem
from dolfinx.mesh import entities_to_geometry

from bcfem.geometry.substrate import (
    AXIS,
    BOTTOM,
    CONTACT,
    CORNER,
    FAR,
    OUTER_TOP,
    SUBSTRATE,
    WETTED,
    SubstrateGeometry,
    create_mesh,
)
from bcfem.mpi import global_sum

FACETS = (WETTED, OUTER_TOP, FAR, BOTTOM, AXIS)


def measures(data) -> dict:
    """The volume of revolution int 2 pi R dA of the cells and the length of each tagged facet group."""
    msh = data.mesh
    x = ufl.SpatialCoordinate(msh)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=data.cell_tags)
    ds = ufl.Measure("ds", domain=msh, subdomain_data=data.facet_tags)
    one = fem.Constant(msh, 1.0)
    result = {SUBSTRATE: global_sum(fem.form(2 * math.pi * x[0] * dx(SUBSTRATE)))}
    result.update({tag: global_sum(fem.form(one * ds(tag))) for tag in FACETS})
    return result


def exact_measures(g: SubstrateGeometry) -> dict:
    r0, width, height = g.contact_radius, g.width, g.height
    return {SUBSTRATE: math.pi * width**2 * height, WETTED: r0, OUTER_TOP: width - r0,
            FAR: height, BOTTOM: width, AXIS: height}


def owned(msh, dim: int, entities: np.ndarray) -> np.ndarray:
    return entities[entities < msh.topology.index_map(dim).size_local]


def smallest_top_facet(data):
    """(length, endpoints) of the shortest facet on the top surface, over all ranks."""
    msh = data.mesh
    top = np.concatenate([data.facet_tags.find(WETTED), data.facet_tags.find(OUTER_TOP)])
    ends = msh.geometry.x[entities_to_geometry(msh, 1, top)[:, :2]][..., :2]
    lengths = np.linalg.norm(ends[:, 0] - ends[:, 1], axis=1)
    local = (lengths.min(), ends[lengths.argmin()]) if len(top) else (np.inf, None)
    return min(msh.comm.allgather(local), key=lambda pair: pair[0])


GEOMETRIES = [SubstrateGeometry(), SubstrateGeometry(thickness=0.1),
              SubstrateGeometry(contact_radius=2.0, size_factor=4.0, thickness=1.0, order=2)]


@pytest.mark.mpi
@pytest.mark.parametrize("geometry", GEOMETRIES, ids=["half-space", "layer-r0/h=10", "R0=2-order2"])
def test_volume_and_facet_lengths_are_exact(geometry):
    data = create_mesh(geometry, MPI.COMM_WORLD)
    measured, exact = measures(data), exact_measures(geometry)
    for tag, value in exact.items():
        assert measured[tag] == pytest.approx(value, rel=1e-10), tag
    regions = MPI.COMM_WORLD.allreduce(set(data.cell_tags.values.tolist()), op=MPI.BOR)
    assert regions == {SUBSTRATE}


@pytest.mark.mpi
@pytest.mark.parametrize("geometry", GEOMETRIES[:2], ids=["half-space", "layer-r0/h=10"])
def test_contact_point_is_a_tagged_vertex_beside_the_smallest_top_facet(geometry):
    data = create_mesh(geometry, MPI.COMM_WORLD)
    msh, points = data.mesh, data.ridge_tags
    contact = owned(msh, 0, points.find(CONTACT))
    assert msh.comm.allreduce(len(contact), op=MPI.SUM) == 1
    assert msh.comm.allreduce(len(owned(msh, 0, points.find(CORNER))), op=MPI.SUM) == 4
    r0 = geometry.contact_radius
    for node in entities_to_geometry(msh, 0, contact).ravel():
        assert msh.geometry.x[node, :2] == pytest.approx([r0, 0.0], abs=1e-14)

    length, ends = smallest_top_facet(data)
    assert min(np.linalg.norm(ends - [r0, 0.0], axis=1)) < 1e-14 * r0
    h_min = geometry.size_contact * r0
    assert h_min / 1.5 < length < 1.5 * h_min


@pytest.mark.mpi
def test_two_ranks_build_the_serial_mesh():
    geometry = SubstrateGeometry(thickness=0.5, size_contact=1e-3)
    parallel = create_mesh(geometry, MPI.COMM_WORLD)
    serial = create_mesh(geometry, MPI.COMM_SELF)
    assert (parallel.mesh.topology.index_map(2).size_global
            == serial.mesh.topology.index_map(2).size_global)
    alone = measures(serial)
    for tag, value in measures(parallel).items():
        assert value == pytest.approx(alone[tag], rel=1e-12), tag


def cell_count(geometry: SubstrateGeometry) -> int:
    return create_mesh(geometry, MPI.COMM_SELF).mesh.topology.index_map(2).size_global


def test_cell_count_grows_like_the_log_of_the_smallest_size():
    """Geometric grading: each decade of size_contact adds about (2 pi / (g-1)^2) ln 10 / (sqrt 3 / 2) cells."""
    counts = [cell_count(SubstrateGeometry(size_contact=h)) for h in (1e-2, 1e-3, 1e-4)]
    report = f"cells for size_contact 1e-2, 1e-3, 1e-4: {counts}"
    assert counts[2] < 3 * counts[0], report  # 1 / size_contact grew 100 times
    first, second = counts[1] - counts[0], counts[2] - counts[1]
    assert abs(second - first) < 0.2 * first, report  # the same number of cells per decade


def test_refine_halves_every_size():
    geometry = SubstrateGeometry(size_contact=1e-2)
    fine = SubstrateGeometry(size_contact=1e-2, refine=1)
    assert fine.element_size(0.5) == pytest.approx(geometry.element_size(0.5) / 2)
    assert 3.5 < cell_count(fine) / cell_count(geometry) < 4.5
    length, _ = smallest_top_facet(create_mesh(fine, MPI.COMM_SELF))
    assert 0.5e-2 / 1.5 < length < 1.5 * 0.5e-2


def test_size_wetted_caps_the_wetted_top_only():
    """size_wetted bounds the facets on R < R0 (a blister's free membrane lies there), leaves the
    grading at the contact point and beyond the wetted top as it was, and the cell estimate
    follows it (within 15 %)."""
    geometry = SubstrateGeometry(size_contact=1e-2, growth=1.25, size_wetted=0.05)
    data = create_mesh(geometry, MPI.COMM_SELF)
    msh = data.mesh
    wetted = data.facet_tags.find(WETTED)
    ends = msh.geometry.x[entities_to_geometry(msh, 1, wetted)[:, :2]][..., :2]
    lengths = np.linalg.norm(ends[:, 0] - ends[:, 1], axis=1)
    assert lengths.max() < 1.3 * 0.05 and lengths.sum() == pytest.approx(1.0, rel=1e-12)
    plain = SubstrateGeometry(size_contact=1e-2, growth=1.25)
    assert geometry.size_at(1.0, 0.0) == plain.size_at(1.0, 0.0)
    assert geometry.size_at(5.0, -3.0) == plain.size_at(5.0, -3.0)
    assert geometry.size_at(0.0, 0.0) == pytest.approx(0.05) and plain.size_at(0.0, 0.0) == pytest.approx(0.26)
    cells = msh.topology.index_map(2).size_global
    assert abs(geometry.estimated_cells() / cells - 1) < 0.15, (geometry.estimated_cells(), cells)


def test_thin_layer_far_size_resolves_its_thickness():
    assert SubstrateGeometry().far_size == pytest.approx(1.0)  # L R0 / 10
    assert SubstrateGeometry(thickness=0.1).far_size == pytest.approx(0.025)  # four elements across


@pytest.mark.parametrize("kwargs, word", [
    ({"size_factor": 1.0}, "size_factor"),
    ({"size_factor": 0.5}, "size_factor"),
    ({"contact_radius": 0.0}, "contact_radius"),
    ({"thickness": 0.0}, "thickness"),
    ({"thickness": -0.2}, "thickness"),
    ({"size_contact": 0.0}, "size_contact"),
    ({"size_contact": -1e-3}, "size_contact"),
    ({"size_contact": 1.0}, "size_contact"),  # = the default size_far
    ({"size_far": -1.0}, "size_far"),
    ({"size_contact": 0.1, "size_far": 0.1}, "size_far"),
    ({"thickness": 0.5, "size_far": 1.0}, "size_far"),  # an element thicker than the layer
    ({"growth": 1.0}, "growth"),
    ({"growth": 2.5}, "growth"),
    ({"refine": -1}, "refine"),
    ({"refine": 0.5}, "refine"),
    ({"order": 3}, "order"),
])
def test_bad_geometry_is_refused_before_meshing(kwargs, word):
    with pytest.raises(ValueError, match=word):
        SubstrateGeometry(**kwargs)


@pytest.mark.serial
def test_geometry_cli_writes_mesh_and_preview(tmp_path):
    out = tmp_path / "s.msh"
    res = subprocess.run([sys.executable, "-m", "bcfem.geometry", "substrate", "--thickness", "0.2",
                          "--size-contact", "1e-3", "-o", str(out)], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert out.stat().st_size > 1000 and out.with_suffix(".png").stat().st_size > 1000
    res = subprocess.run([sys.executable, "-m", "bcfem.geometry", "substrate", "--size-factor", "1", "-o",
                          str(tmp_path / "bad.msh")], capture_output=True, text=True, timeout=300)
    assert res.returncode == 2 and "size_factor" in res.stderr and not (tmp_path / "bad.msh").exists()
