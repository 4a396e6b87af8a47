"""The double-chamber crater: exact cavity volume and wall areas, named groups, clear errors, chamber volumes."""

import functools
import math
import subprocess
import sys

from mpi4py import MPI

import numpy as np
import pytest
import ufl
from dolfinx import fem
from dolfinx.mesh import entities_to_geometry

from bcfem.geometry.double_crater import (
    AXIS,
    BOTTOM,
    CORNER,
    EQUATOR,
    NECK,
    OUTER,
    PROTUBERANCE,
    RIM,
    ROOF,
    ROOF_RIM,
    SIDEWALL,
    SPECIMEN,
    TOP,
    WALLS,
    DoubleCraterGeometry,
    cap_volume,
    create_mesh,
)
from bcfem.kinematics.solid import AxisymmetricSolid
from bcfem.mpi import global_sum
from bcfem.physics.cavity import Cavity
from bcfem.scenes.crater_double.chambers import ChamberSplit, plug_flux

DEFAULT = DoubleCraterGeometry()
# the centre above the roof (a cap smaller than a hemisphere), and another scale with a wide crater
HIGH_CENTRE = DoubleCraterGeometry(crater_radius=0.52, protuberance_radius=0.45, gap=0.6)
WIDE = DoubleCraterGeometry(crater_height=2.0, crater_radius=1.5, protuberance_radius=0.8, gap=0.5,
                            size_contact=0.01, size_corner=0.01)
GEOMETRIES = {"dissertation": DEFAULT, "centre-above-roof": HIGH_CENTRE, "wide": WIDE}


@functools.cache
def mesh_of(geometry, serial=False):
    return create_mesh(geometry, MPI.COMM_SELF if serial else MPI.COMM_WORLD)


def solid(data, displacement=None):
    """Kinematics of a P2 displacement given as a callable of the reference coordinates (None: at rest)."""
    V = fem.functionspace(data.mesh, ("Lagrange", 2, (2,)))
    u = fem.Function(V)
    if displacement is not None:
        u.interpolate(displacement)
    return AxisymmetricSolid(u, quadrature_degree=4, facet_tags=data.facet_tags)


def cavity_volume(kin) -> float:
    """The Cavity functional over the three walls (normals out of the solid, into the cavity)."""
    return global_sum(fem.form(sum(Cavity(wall).volume(kin) for wall in WALLS)))


def measures(data) -> dict:
    """The body's volume of revolution and the area 2 pi r ds of every facet group."""
    x = ufl.SpatialCoordinate(data.mesh)
    dx = ufl.Measure("dx", domain=data.mesh, subdomain_data=data.cell_tags)
    ds = ufl.Measure("ds", domain=data.mesh, subdomain_data=data.facet_tags)
    area = 2 * math.pi * x[0]
    result = {SPECIMEN: global_sum(fem.form(area * dx(SPECIMEN)))}
    result.update({tag: global_sum(fem.form(area * ds(tag))) for tag in
                   (BOTTOM, SIDEWALL, ROOF, PROTUBERANCE, TOP, AXIS, OUTER)})
    return result


def owned(msh, dim, entities):
    return entities[entities < msh.topology.index_map(dim).size_local]


def test_dissertation_ratios_and_closed_forms():
    g = DEFAULT
    assert (g.r0, g.R0, g.s) == pytest.approx((0.52, 0.5, 0.03), rel=1e-15)
    assert (g.specimen_radius, g.specimen_height) == pytest.approx((2.6, 5.0), rel=1e-15)
    # the ball reaches 0.03 H past the roof: the protuberance is the zone of height h = 0.97 H
    h = 0.97
    assert g.protuberance_height == pytest.approx(h)
    assert g.neck_radius == pytest.approx(math.sqrt(0.5**2 - 0.47**2), rel=1e-14)
    assert g.protuberance_volume == pytest.approx(math.pi * h**2 * (1.5 - h) / 3, rel=1e-14)
    assert g.crater_volume == pytest.approx(math.pi * (0.2704 - h**2 * 0.53 / 3), rel=1e-14)
    assert g.contact_height == pytest.approx(0.53)
    # the ball's volume by slices, pi int rho(z)^2 dz over [s, H]
    z = np.linspace(g.s, g.crater_height, 20001)
    rho2 = np.array([g.protuberance_radius_at(t) ** 2 for t in z])
    assert math.pi * np.trapezoid(rho2, z) == pytest.approx(g.protuberance_volume, rel=1e-7)
    assert cap_volume(1.0, 2.0) == pytest.approx(4 * math.pi / 3)
    for z in (0.0, 0.02, 0.3, 0.53, 1.0):
        lower, upper = g.chamber_volumes(z)
        assert lower + upper == pytest.approx(g.crater_volume, rel=1e-14)
    assert g.chamber_volumes(0.0)[0] == 0.0 and g.chamber_volumes(1.0)[1] == pytest.approx(0.0, abs=1e-15)
    assert HIGH_CENTRE.widest_radius == pytest.approx(HIGH_CENTRE.neck_radius)  # the equator is cut off


@pytest.mark.mpi
@pytest.mark.parametrize("name", GEOMETRIES)
def test_cavity_volume_and_wall_areas_are_exact(name):
    g = GEOMETRIES[name]
    data = mesh_of(g)
    # second-order arcs: the volume error is that of the quadratic interpolation of the circle
    assert cavity_volume(solid(data)) == pytest.approx(g.crater_volume, rel=2e-8)
    measured = measures(data)
    Rs, Hs = g.specimen_radius, g.specimen_height
    exact = {SPECIMEN: g.specimen_volume, BOTTOM: math.pi * (Rs**2 - g.r0**2), SIDEWALL: g.sidewall_area,
             ROOF: g.roof_area, PROTUBERANCE: g.protuberance_area, TOP: math.pi * Rs**2, AXIS: 0.0,
             OUTER: 2 * math.pi * Rs * Hs}
    for tag, value in exact.items():
        assert measured[tag] == pytest.approx(value, rel=2e-8, abs=1e-14), tag
    comm, points = data.mesh.comm, data.ridge_tags
    counts = {key: comm.allreduce(len(owned(data.mesh, 0, points.find(key))), op=MPI.SUM)
              for key in (RIM, ROOF_RIM, NECK, EQUATOR, CORNER)}
    equator = int(g.centre_height < g.crater_height)
    assert counts == {RIM: 1, ROOF_RIM: 1, NECK: 1, EQUATOR: equator, CORNER: 4}
    where = {RIM: (g.r0, 0.0), ROOF_RIM: (g.r0, g.crater_height), NECK: (g.neck_radius, g.crater_height),
             EQUATOR: (g.R0, g.centre_height)}
    for key, point in where.items():
        for node in entities_to_geometry(data.mesh, 0, points.find(key)).ravel():
            assert data.mesh.geometry.x[node, :2] == pytest.approx(point, abs=1e-12), key


@pytest.mark.mpi
def test_without_a_protuberance_the_crater_is_a_plain_cylinder():
    g = DoubleCraterGeometry(protuberance_radius=0.0, size_wall=0.08, size_contact=0.02, size_corner=0.02)
    assert not g.has_protuberance and g.protuberance_volume == 0.0 and g.neck_radius == 0.0
    assert g.crater_volume == pytest.approx(math.pi * g.r0**2 * g.crater_height, rel=1e-15)
    data = mesh_of(g)
    assert cavity_volume(solid(data)) == pytest.approx(g.crater_volume, rel=1e-12)  # straight walls: exact
    measured = measures(data)
    assert measured[ROOF] == pytest.approx(math.pi * g.r0**2, rel=1e-12) and measured[PROTUBERANCE] == 0.0
    assert measured[SIDEWALL] == pytest.approx(g.sidewall_area, rel=1e-12)
    comm, points = data.mesh.comm, data.ridge_tags
    counts = {key: comm.allreduce(len(owned(data.mesh, 0, points.find(key))), op=MPI.SUM)
              for key in (RIM, ROOF_RIM, NECK, EQUATOR, CORNER)}
    assert counts == {RIM: 1, ROOF_RIM: 1, NECK: 0, EQUATOR: 0, CORNER: 4}


def facet_lengths_near(data, tag, point):
    """The length of the facet of ``tag`` whose midpoint is nearest ``point``, over all ranks."""
    msh = data.mesh
    ends = msh.geometry.x[entities_to_geometry(msh, 1, data.facet_tags.find(tag))[:, :2]][..., :2]
    distance = np.linalg.norm(ends.mean(axis=1) - point, axis=1)
    local = (distance.min(), np.linalg.norm(ends[distance.argmin(), 0] - ends[distance.argmin(), 1])) \
        if len(ends) else (np.inf, None)
    return min(msh.comm.allgather(local), key=lambda pair: pair[0])[1]


@pytest.mark.mpi
def test_refined_where_the_sidewall_meets_the_protuberance_and_at_the_rims():
    g = DEFAULT
    data = mesh_of(g)
    H, zc = g.crater_height, g.contact_height
    checks = [(SIDEWALL, (g.r0, zc), g.size_contact), (PROTUBERANCE, (g.R0, zc), g.size_contact),
              (SIDEWALL, (g.r0, 0.0), g.size_corner), (SIDEWALL, (g.r0, H), g.size_corner),
              (ROOF, (g.neck_radius, H), g.size_corner), (SIDEWALL, (g.r0, 0.8 * H), g.size_wall)]
    for tag, point, size in checks:
        length = facet_lengths_near(data, tag, np.array(point))
        assert size * H / 1.5 < length < 1.5 * size * H, (tag, point, length)


@pytest.mark.mpi
def test_two_ranks_build_the_serial_mesh():
    parallel, serial = mesh_of(DEFAULT), mesh_of(DEFAULT, serial=True)
    assert (parallel.mesh.topology.index_map(2).size_global == serial.mesh.topology.index_map(2).size_global)
    alone = measures(serial)
    for tag, value in measures(parallel).items():
        assert value == pytest.approx(alone[tag], rel=1e-12, abs=1e-14), tag
    assert cavity_volume(solid(parallel)) == pytest.approx(cavity_volume(solid(serial)), rel=1e-12)


@pytest.mark.mpi
@pytest.mark.parametrize("stretch_r, stretch_z", [(1.1, 0.8), (0.9, 1.05)])
def test_current_cavity_volume_under_an_affine_map(stretch_r, stretch_z):
    """Nanson's formula on the three walls: an affine map scales the cavity by lr^2 lz."""
    kin = solid(mesh_of(DEFAULT), lambda x: np.vstack([(stretch_r - 1) * x[0], (stretch_z - 1) * x[1]]))
    assert cavity_volume(kin) == pytest.approx(DEFAULT.crater_volume * stretch_r**2 * stretch_z, rel=2e-8)


@pytest.mark.parametrize("kwargs, word", [
    ({"crater_height": 0.0}, "crater_height"),
    ({"protuberance_radius": 0.52}, "protuberance_radius"),  # R0 = r0: no gap to the sidewall
    ({"protuberance_radius": 0.6}, "protuberance_radius"),
    ({"gap": 0.0}, "gap"),  # the ball on the plate
    ({"gap": -0.01}, "gap"),
    ({"gap": 1.0}, "gap"),
    ({"protuberance_radius": 0.45, "gap": 0.05}, "reach the roof"),  # s + 2 R0 = 0.95 H < H
    ({"protuberance_radius": 0.485, "gap": 0.03}, "reach the roof"),  # s + 2 R0 = H: a touching point
    ({"crater_radius": 0.0}, "crater_radius"),
    ({"radius": 0.52}, "radius"),
    ({"height": 1.0}, "height"),
    ({"size_contact": 0.0}, "size_contact"),
    ({"size_corner": 0.03}, "size_corner"),
    ({"size_wall": 0.5}, "size_wall"),
    ({"order": 3}, "order"),
])
def test_bad_geometry_is_refused_before_meshing(kwargs, word):
    with pytest.raises(ValueError, match=word):
        DoubleCraterGeometry(**kwargs)


@pytest.mark.serial
def test_geometry_cli_writes_mesh_and_preview(tmp_path):
    out = tmp_path / "d.msh"
    res = subprocess.run([sys.executable, "-m", "bcfem.geometry", "double-crater", "--crater-height", "2",
                          "--size-contact", "0.01", "-o", str(out)], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert out.stat().st_size > 1000 and out.with_suffix(".png").stat().st_size > 1000
    assert "$PhysicalNames" in out.read_text() and '"protuberance"' in out.read_text()
    res = subprocess.run([sys.executable, "-m", "bcfem.geometry", "double-crater", "--gap", "0", "-o",
                          str(tmp_path / "bad.msh")], capture_output=True, text=True, timeout=300)
    assert res.returncode == 2 and "gap" in res.stderr and not (tmp_path / "bad.msh").exists()


# the chambers C1 (plate) and C2 (roof) of the split cavity


def split_of(data):
    return ChamberSplit(data.mesh, data.facet_tags, SIDEWALL, ROOF, PROTUBERANCE)


def test_plug_flux_closed_forms():
    # a horizontal annulus at height z: z pi (r_w^2 - r_b^2)
    assert plug_flux((0.3, 0.5), (0.52, 0.5)) == pytest.approx(0.5 * math.pi * (0.52**2 - 0.3**2), rel=1e-14)
    # the upward cone from the apex (0, 0) to the circle (R, h): int z 2 pi r dr = 2 pi R^2 h / 3
    assert plug_flux((0.0, 0.0), (2.0, 3.0)) == pytest.approx(2 * math.pi * 4 * 3 / 3, rel=1e-14)
    # a closed gap, or a cylindrical plug, contributes nothing
    assert plug_flux((0.5, 0.53), (0.5, 0.53)) == 0.0 and plug_flux((0.5, 0.5), (0.5, 0.6)) == 0.0


@pytest.mark.mpi
def test_chamber_volumes_at_rest_for_splits_at_chosen_heights():
    """At rest the sidewall's walls carry no flux (N_z = 0): C1's walls give
    V_C1(Z_b) - Z_b pi (r0^2 - rho_b^2), the chamber below the plane Z_b less its flat plug."""
    g = DEFAULT
    data = mesh_of(g)
    split = split_of(data)
    kin = solid(data)
    forms = [fem.form(chamber.volume(kin)) for chamber in split.chambers()]  # compiled once
    for z in (0.02, 0.2, g.contact_height, 0.75, 0.99):
        Zw, Zb = split.move(z, z)
        assert abs(Zw - z) < g.size_wall and abs(Zb - z) < g.size_wall
        lower, upper = (global_sum(form) for form in forms)
        rho = g.protuberance_radius_at(Zb)
        plug = plug_flux((rho, Zb), (g.r0, Zb))
        exact_lower, exact_upper = g.chamber_volumes(Zb)
        # the error of the quadratic arcs, relative to the whole cavity
        assert lower == pytest.approx(exact_lower - plug, rel=0, abs=1e-8 * g.crater_volume), z
        assert upper == pytest.approx(exact_upper + plug, rel=0, abs=1e-8 * g.crater_volume), z
        assert lower + upper == pytest.approx(g.crater_volume, rel=2e-8)
    assert split.move(g.contact_height, g.contact_height)[1] == pytest.approx(g.centre_height, abs=1e-12)


@pytest.mark.mpi
def test_chambers_add_up_to_the_cavity_for_any_split():
    """For any split, also inside facets and in a deformed state, V_C1 + V_C2 = V."""
    data = mesh_of(DEFAULT)
    split = split_of(data)
    kin = solid(data, lambda x: np.vstack([0.05 * x[0] * np.sin(3 * x[1]), -0.1 * x[1] + 0.02 * x[0] ** 2]))
    whole = cavity_volume(kin)
    forms = [fem.form(chamber.volume(kin)) for chamber in split.chambers()]
    for Zw, Zb in [(0.0, 0.0), (0.123456, 0.654321), (0.53, 0.5), (1.0, 1.0), (0.777, 0.031)]:
        split.sidewall_height.value, split.protuberance_height.value = Zw, Zb
        lower, upper = (global_sum(form) for form in forms)
        assert lower + upper == pytest.approx(whole, rel=1e-12)
    assert lower != pytest.approx(0.0) and upper != pytest.approx(0.0)


@pytest.mark.mpi
def test_sidewall_band_under_a_shear_is_its_closed_form():
    """u_r = beta r z / r0 tilts the sidewall to r = r0 + beta Z: the band Z1 < Z < Z2 of the
    sidewall adds -2 pi beta [r0 Z^2 / 2 + beta Z^3 / 3] from Z1 to Z2 to the volume of C1."""
    g, beta = DEFAULT, 0.1
    data = mesh_of(g)
    split = split_of(data)
    kin = solid(data, lambda x: np.vstack([beta * x[0] * x[1] / g.r0, 0 * x[1]]))
    lower = fem.form(split.chambers()[0].volume(kin))

    def primitive(Z):
        return -2 * math.pi * beta * (g.r0 * Z**2 / 2 + beta * Z**3 / 3)

    Z1, _ = split.move(0.3, 0.5)
    below = global_sum(lower)
    Z2, _ = split.move(0.7, 0.5)
    assert global_sum(lower) - below == pytest.approx(primitive(Z2) - primitive(Z1), rel=1e-10)


@pytest.mark.mpi
def test_each_chamber_holds_its_own_gas():
    """Two ideal gases, one per chamber (sealed apart, each with its own pressure and amount),
    in one model: each pressure's row is Boyle's law of its own chamber, zero at p_i = n_i / V_i."""
    from bcfem.physics.context import Context
    from bcfem.physics.fluids import IdealGas

    g = DEFAULT
    data = mesh_of(g)
    split = split_of(data)
    split.move(g.contact_height, g.contact_height)
    kin = solid(data)
    ctx = Context(kin.u, kin)
    c1, c2 = split.chambers()
    amounts = {"p_c1": 0.05, "p_c2": 0.2}
    gases = [IdealGas(c1, amounts["p_c1"], "p_c1"), IdealGas(c2, amounts["p_c2"], "p_c2")]
    volumes = [global_sum(fem.form(c.volume(kin))) for c in (c1, c2)]
    energy = sum(gas.energy(ctx) for gas in gases)
    for (name, amount), volume in zip(amounts.items(), volumes):
        ctx.real_state(name).x.array[:] = amount / volume
    for name, p in ((n, ctx.real_state(n)) for n in amounts):
        one = fem.Function(p.function_space)
        one.x.array[:] = 1.0
        row = global_sum(fem.form(ufl.derivative(energy, p, one)))
        assert row == pytest.approx(0.0, abs=1e-12), name


@pytest.mark.mpi
def test_a_chamber_enclosed_by_the_specimen_pulls_on_nothing():
    """The net force of a chamber's gas on the specimen is (p - p_a) times the derivative of
    its volume along a rigid lift of the specimen. With the sidewall's split point moved onto
    the protuberance's (the gap closed there), C2 is enclosed by the specimen alone: its
    volume does not change under the lift, whatever its pressure; C1, bounded by the plate
    under the hanging protuberance, changes by the plate's whole crater area pi r0^2."""
    g = DEFAULT
    data = mesh_of(g)
    split = split_of(data)
    Zw, Zb = split.move(g.centre_height, g.centre_height)
    rb = g.protuberance_radius_at(Zb)
    width = g.r0 - rb

    def closing(x):
        """Carries the sidewall point (r0, Zw) onto the protuberance point (rb, Zb); the
        protuberance (r <= rb) stays where it is."""
        bump = np.clip((x[0] - rb) / width, 0, 1) * np.exp(-(((x[1] - Zw) / 0.1) ** 2))
        return np.vstack([-width * bump, (Zb - Zw) * bump])

    kin = solid(data, closing)
    lift = fem.Function(kin.u.function_space)
    lift.interpolate(lambda x: np.vstack([0 * x[0], 1 + 0 * x[0]]))
    c1, c2 = split.chambers()
    rates = [global_sum(fem.form(ufl.derivative(c.volume(kin), kin.u, lift))) for c in (c1, c2)]
    assert rates[1] == pytest.approx(0.0, abs=1e-12 * g.crater_volume)
    assert rates[0] == pytest.approx(math.pi * g.r0**2, rel=1e-10)
    # at rest the gap is open: C2 alone is not closed, and the lift changes its volume by
    # the open plug's projected area
    rest = solid(data)
    open_rate = global_sum(fem.form(ufl.derivative(c2.volume(rest), rest.u, lift)))
    assert abs(open_rate) == pytest.approx(math.pi * (g.r0**2 - rb**2), rel=1e-10)
