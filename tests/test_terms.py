"""Standard battery for every energy term: closed-form value, Taylor tests, rank counts.

Every term of the library is here (:func:`test_the_battery_covers_every_term`):

* its value at a configuration where the energy is known in closed form (a
  uniform stretch of the membrane, a homogeneous deformation of a small
  axisymmetric solid, whose cavity below is a cylinder, or a polynomial one of a
  substrate under a drop);
* Taylor tests through a :class:`bcfem.solver.problem.Problem` holding the term
  alone, in all its states (displacement and multipliers): the assembled
  residual is the derivative of the energy and the assembled tangent that of
  the residual (remainders O(e^2): rate 2 when e halves);
* under ``mpirun -n 2`` (marker ``mpi``): the closed forms hold on the
  distributed mesh, and the Taylor numbers (energy, residual and tangent) are
  those of the same model on COMM_SELF.
"""

import inspect
import math

from mpi4py import MPI

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from helpers import assert_second_order, rate, taylor

from bcfem import (
    AxisymmetricMembrane,
    Context,
    Gent,
    Kinematics,
    MembraneStrain,
    MooneyRivlin,
    NeoHookean,
    PressureVolume,
    SurfaceTension,
    Term,
    find_term,
    global_sum,
)
from bcfem.kinematics.solid import AxisymmetricSolid
from bcfem.physics import composite, energies, fluids, linear_solid, sessile_drop, viscosity
from bcfem.physics.cavity import Cavity
from bcfem.physics.composite import OnSurface, Scaled
from bcfem.physics.energies import SolidStrain, SolidSurfaceEnergy, WettedSubstrate
from bcfem.physics.fluids import HeldPressure, IdealGas, IncompressibleLiquid, Vacuum
from bcfem.physics.linear_solid import LinearDropLoads, LinearElasticity, LinearSurfaceTension, SubstrateKinematics
from bcfem.physics.materials import NearlyIncompressibleNeoHookean
from bcfem.physics.sessile_drop import SphericalCapDrop
from bcfem.physics.viscosity import Viscosity
from bcfem.solver.problem import Problem

pytestmark = pytest.mark.mpi

# the solid: the rectangle [0, 1] x [Z0, Z0 + H] in (r, z), a cylinder whose bottom face is
# the wall of a cavity closed by the plate z = 0
Z0, H = 1.0, 1.5
CAVITY, TOP, SIDE = 1, 2, 3
KAPPA = 50.0  # a moderate bulk modulus: the mixed pressure's block matters in the Taylor tests


def make_ctx(cells=12, degree=2, comm=MPI.COMM_WORLD):
    """A membrane on R in [0, 1]."""
    msh = mesh.create_interval(comm, cells, [0.0, 1.0])
    V = fem.functionspace(msh, ("Lagrange", degree, (2,)))
    u = fem.Function(V)
    return Context(u, AxisymmetricMembrane(u, quadrature_degree=2 * degree + 4))


def solid_ctx(comm=MPI.COMM_WORLD, cells=3):
    """The cylinder, P2 displacement, its bottom, top and side faces tagged."""
    msh = mesh.create_rectangle(comm, [[0.0, Z0], [1.0, Z0 + H]], [cells, cells], mesh.CellType.triangle)
    msh.topology.create_connectivity(1, 2)
    faces = [(CAVITY, lambda x: np.isclose(x[1], Z0)), (TOP, lambda x: np.isclose(x[1], Z0 + H)),
             (SIDE, lambda x: np.isclose(x[0], 1.0))]
    found = [(mesh.locate_entities_boundary(msh, 1, where), tag) for tag, where in faces]
    facets = np.concatenate([f for f, _ in found])
    order = np.argsort(facets)
    tags = np.concatenate([np.full(f.size, tag, dtype=np.int32) for f, tag in found])
    facet_tags = mesh.meshtags(msh, 1, facets[order], tags[order])
    V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
    u = fem.Function(V, name="displacement")
    return Context(u, AxisymmetricSolid(u, quadrature_degree=4, facet_tags=facet_tags))


def substrate_ctx(comm=MPI.COMM_WORLD, cells=4):
    """A substrate [0, 1] x [-1, 0] under a drop: its top Z = 0 wetted for R < R_DROP, dry beyond
    (small-strain kinematics: :class:`SubstrateKinematics`)."""
    msh = mesh.create_rectangle(comm, [[0.0, -1.0], [1.0, 0.0]], [cells, cells], mesh.CellType.triangle)
    msh.topology.create_connectivity(1, 2)
    top = mesh.locate_entities_boundary(msh, 1, lambda x: np.isclose(x[1], 0.0))
    middle = mesh.compute_midpoints(msh, 1, top)
    tags = np.where(middle[:, 0] < R_DROP, WETTED, DRY).astype(np.int32)
    order = np.argsort(top)
    V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
    u = fem.Function(V, name="displacement")
    kin = SubstrateKinematics(u, quadrature_degree=6, facet_tags=mesh.meshtags(msh, 1, top[order], tags[order]))
    return Context(u, kin)


SOLID_MATERIAL = NearlyIncompressibleNeoHookean(mu=1.0, kappa=KAPPA)
#: the substrate's top: wetted for R < R_DROP (the drop's contact radius), dry beyond
WETTED, DRY, R_DROP = 4, 5, 0.5
THETA = 1.1  # the drop's contact angle

#: term -> (body, factory(ctx)); the body is "membrane" or "solid"
TERMS = {
    "neo-hookean": ("membrane", lambda ctx: MembraneStrain(NeoHookean())),
    "gent": ("membrane", lambda ctx: MembraneStrain(Gent(Jm=20.0))),
    "mooney-rivlin": ("membrane", lambda ctx: MembraneStrain(MooneyRivlin(C1=0.4, C2=0.15))),
    "surface-tension": ("membrane", lambda ctx: SurfaceTension(0.7)),
    "pressure-volume": ("membrane", lambda ctx: PressureVolume()),
    "wetted-substrate": ("membrane", lambda ctx: WettedSubstrate(-0.4)),
    "solid-strain": ("solid", lambda ctx: SolidStrain(SOLID_MATERIAL)),
    "solid-surface-energy": ("solid", lambda ctx: SolidSurfaceEnergy(0.8, TOP)),
    "ideal-gas": ("solid", lambda ctx: IdealGas(Cavity(CAVITY), sealed_volume=2.5)),
    "incompressible-liquid": ("solid", lambda ctx: IncompressibleLiquid(Cavity(CAVITY), sealed_volume=2.5)),
    "vacuum": ("solid", lambda ctx: Vacuum(Cavity(CAVITY))),
    "held-pressure": ("solid", lambda ctx: HeldPressure(Cavity(CAVITY), HELD)),
    "viscosity": ("solid", lambda ctx: Viscosity(ctx.u)),
    "on-surface": ("membrane", lambda ctx: OnSurface(SurfaceTension(0.7), ctx.kin, "itself")),
    "scaled": ("membrane", lambda ctx: Scaled(MembraneStrain(NeoHookean()), "stiffness", 2.5)),
    "linear-elasticity": ("substrate", lambda ctx: LinearElasticity(mu=1.0, nu=0.3)),
    "linear-surface-tension": ("substrate", lambda ctx: LinearSurfaceTension(0.6, WETTED)),
    "linear-drop-loads": ("substrate", lambda ctx: LinearDropLoads(0.8, THETA, R_DROP, WETTED, math.cos(THETA))),
    "spherical-cap-drop": ("substrate", lambda ctx: SphericalCapDrop(0.8, 0.05, R_DROP, WETTED)),
}
#: terms linear in their states: their Taylor remainders are round-off
LINEAR = {"linear-drop-loads"}
BODIES = {"membrane": make_ctx, "solid": solid_ctx, "substrate": substrate_ctx}

#: a cavity's held pressure (a liquid's vapour pressure, over p_a)
HELD = 0.023
#: values of the states and run-time constants in the Taylor tests (where a term uses them)
REAL_STATES = {"pressure": 1.3, "fluid_pressure": 1.4, "cap_slope": 0.45, "drop_pressure": 1.1}
CONSTANTS = {"volume_target": 0.3, "viscosity": 1.7, "vacuum_load": 0.6}


# -- the battery covers the library ----------------------------------------------------------
def library_terms():
    """Every class of the term modules that has an energy of its own (not only Term's)."""
    modules = (energies, fluids, viscosity, composite, linear_solid, sessile_drop)
    return {cls for module in modules for _, cls in inspect.getmembers(module, inspect.isclass)
            if cls.__module__ == module.__name__ and getattr(cls, "energy", Term.energy) is not Term.energy}


def test_the_battery_covers_every_term():
    tested = set()
    for body, factory in TERMS.values():
        ctx = BODIES[body]()
        term = factory(ctx)
        assert isinstance(term, Term) and isinstance(ctx.kin, Kinematics), type(term).__name__
        tested.add(type(term))
    assert library_terms() <= tested, library_terms() - tested


def test_terms_declare_their_multipliers():
    cavity = Cavity(CAVITY)
    assert SolidStrain(SOLID_MATERIAL).multipliers == ("solid_pressure",)
    assert IdealGas(cavity, 1.0).multipliers == IncompressibleLiquid(cavity, 1.0).multipliers == ("fluid_pressure",)
    assert IdealGas(cavity, 1.0, pressure_name="gas").multipliers == ("gas",)
    assert PressureVolume().multipliers == ("pressure",)
    for term in (MembraneStrain(NeoHookean()), SurfaceTension(1.0), WettedSubstrate(1.0),
                 SolidSurfaceEnergy(1.0, TOP), Vacuum(cavity)):
        assert term.multipliers == ()


def test_the_problem_collects_the_multipliers_in_state_order():
    ctx = solid_ctx()
    terms = [IdealGas(Cavity(CAVITY), 2.5), SolidStrain(SOLID_MATERIAL), SolidSurfaceEnergy(0.1, TOP)]
    with Problem(ctx, terms, [], "bcfem_test_terms_collect_") as problem:
        assert problem.names == ["displacement", "fluid_pressure", "solid_pressure"]
        assert problem.multipliers == ("fluid_pressure", "solid_pressure")
        p1 = ctx.states["solid_pressure"].function_space.dofmap.index_map.size_global
        assert p1 == 4 * 4  # P1 on the 3 x 3 rectangle's vertices
        assert problem.global_size(problem.multipliers) == 1 + p1
        assert problem.global_size(["displacement"]) == 2 * 7 * 7
        with pytest.raises(ValueError, match="no state 'pressure'"):
            problem.global_size(["pressure"])
        assert problem.bounds == ()


def test_a_replaced_row_is_no_multiplier():
    # under arc-length the pressure's row is the arc-length equation, not the volume constraint
    ctx = make_ctx()
    term = PressureVolume()
    term.energy(ctx)
    p = ctx.real_state("pressure")
    row = (p - 1.0) * ufl.TestFunction(p.function_space) * ufl.dx(domain=ctx.mesh)
    with Problem(ctx, [MembraneStrain(NeoHookean()), term], [], "bcfem_test_terms_rows_",
                 rows={"pressure": row}) as problem:
        assert problem.multipliers == ()


def test_find_term_by_type():
    strain, tension = MembraneStrain(NeoHookean()), SurfaceTension(0.5)
    assert find_term([tension, strain], MembraneStrain) is strain
    with pytest.raises(LookupError, match="exactly one MembraneStrain.*found 0"):
        find_term([tension], MembraneStrain)
    with pytest.raises(LookupError, match="found 2"):
        find_term([strain, tension, strain], MembraneStrain)


# -- closed forms: the membrane --------------------------------------------------------------
def uniform_stretch_W(material, lam):
    I1 = 2 * lam**2 + lam**-4
    if isinstance(material, Gent):
        return -0.5 * material.Jm * math.log(1 - (I1 - 3) / material.Jm)
    return 0.5 * (I1 - 3)


@pytest.mark.parametrize("name", ["neo-hookean", "gent"])
def test_strain_energy_uniform_stretch(name):
    ctx = make_ctx()
    term = TERMS[name][1](ctx)
    lam = 1.3
    ctx.u.interpolate(lambda x: np.vstack([(lam - 1) * x[0], 0 * x[0]]))
    value = global_sum(fem.form(term.energy(ctx)))
    assert value == pytest.approx(math.pi * uniform_stretch_W(term.material, lam), rel=1e-12)


def test_surface_energy_uniform_stretch():
    ctx = make_ctx()
    lam = 1.3
    ctx.u.interpolate(lambda x: np.vstack([(lam - 1) * x[0], 0 * x[0]]))
    assert global_sum(fem.form(SurfaceTension(0.7).energy(ctx))) == pytest.approx(0.7 * math.pi * lam**2, rel=1e-12)


def test_surface_energy_of_a_cap_is_its_area():
    # the hemisphere z = sqrt(1 - r^2) as u_r = 0 is not representable; use a paraboloid, area in closed form
    ctx = make_ctx(cells=64, degree=3)
    h = 0.4
    ctx.u.interpolate(lambda x: np.vstack([0 * x[0], h * (1 - x[0] ** 2)]))
    exact = math.pi / (6 * h * h) * ((1 + 4 * h * h) ** 1.5 - 1)
    assert global_sum(fem.form(SurfaceTension(1.0).energy(ctx))) == pytest.approx(exact, rel=1e-9)


def test_pressure_volume_of_a_cap():
    ctx = make_ctx()
    h, p, v_hat = 0.35, 1.7, 0.2
    ctx.u.interpolate(lambda x: np.vstack([0.1 * x[0] * (1 - x[0]), h * (1 - x[0] ** 2)]))
    term = PressureVolume()
    form = term.energy(ctx)
    ctx.real_state("pressure").x.array[:] = p
    ctx.constant("volume_target").value = v_hat
    # with u_r != 0 the volume under the cap is no simple closed form: integrate in r numerically
    R = np.linspace(0, 1, 200001)
    r, z = R + 0.1 * R * (1 - R), h * (1 - R**2)
    volume = np.trapezoid(2 * np.pi * r * z * np.gradient(r, R), R)
    assert global_sum(fem.form(form)) == pytest.approx(-p * (volume - v_hat), rel=1e-8)
    assert ctx.kin.reference_area == pytest.approx(math.pi, rel=1e-15)


def test_wetted_substrate_is_the_projected_area():
    """r = R + a R^2 moves the edge to r0 = 1 + a: the wetted area is pi r0^2, whatever the
    height of the membrane above it."""
    ctx = make_ctx()
    a, gamma = 0.15, -0.4
    ctx.u.interpolate(lambda x: np.vstack([a * x[0] ** 2, 0.3 * (1 - x[0] ** 2)]))
    value = global_sum(fem.form(WettedSubstrate(gamma).energy(ctx)))
    assert value == pytest.approx(gamma * math.pi * (1 + a) ** 2, rel=1e-12)


# -- closed forms: the solid under the homogeneous deformation r -> lr r, z -> lz z ----------
LR, LZ = 1.1, 0.85
P_SOLID, P_FLUID, V1, SUCTION, C = 0.4, 1.6, 2.5, 0.6, 1.7


def cavity_volume():
    """The cylinder under the bottom face, which moves to radius LR, height LZ Z0."""
    return math.pi * LR**2 * LZ * Z0


def solid_strain_energy():
    I1, J = 2 * LR**2 + LZ**2, LR**2 * LZ
    W = 0.5 * (I1 - 3) - math.log(J) + P_SOLID * (J - 1) - P_SOLID**2 / (2 * KAPPA)
    return math.pi * H * W  # times the reference volume pi R^2 H


def viscosity_energy():
    # (C/2) int |u|^2 dV with u = ((LR - 1) r, (LZ - 1) z) and u_prev = 0
    top = Z0 + H
    return 0.5 * C * 2 * math.pi * ((LR - 1) ** 2 * H / 4 + (LZ - 1) ** 2 * (top**3 - Z0**3) / 6)


HOMOGENEOUS = {
    "solid-strain": solid_strain_energy,
    # the top face's current area, pi LR^2, times gamma
    "solid-surface-energy": lambda: 0.8 * math.pi * LR**2,
    "ideal-gas": lambda: -(P_FLUID - 1) * cavity_volume() + V1 * math.log(P_FLUID),
    "incompressible-liquid": lambda: -(P_FLUID - 1) * (cavity_volume() - V1),
    "vacuum": lambda: SUCTION * cavity_volume(),
    "held-pressure": lambda: -(HELD - 1) * cavity_volume(),
    "viscosity": viscosity_energy,
}


@pytest.mark.parametrize("name", sorted(HOMOGENEOUS))
def test_solid_terms_under_a_homogeneous_deformation(name):
    ctx = solid_ctx()
    term = TERMS[name][1](ctx)
    form = fem.form(term.energy(ctx))
    ctx.u.interpolate(lambda x: np.vstack([(LR - 1) * x[0], (LZ - 1) * x[1]]))
    for state, value in {"solid_pressure": P_SOLID, "fluid_pressure": P_FLUID}.items():
        if state in ctx.states:
            ctx.states[state].x.array[:] = value
    ctx.constant("vacuum_load").value = SUCTION
    ctx.constant("viscosity").value = C
    assert global_sum(form) == pytest.approx(HOMOGENEOUS[name](), rel=1e-12)


def test_solid_surface_energy_of_the_side_and_the_viscous_increment():
    """The side face r = 1 stretches to radius LR and height LZ H: area 2 pi LR LZ H. The
    viscosity's increment is the L2 norm of u - u_prev with the same weight as its energy."""
    ctx = solid_ctx()
    side = fem.form(SolidSurfaceEnergy(1.0, SIDE).energy(ctx))
    viscosity = Viscosity(ctx.u)
    viscosity.energy(ctx)
    ctx.u.interpolate(lambda x: np.vstack([(LR - 1) * x[0], (LZ - 1) * x[1]]))
    assert global_sum(side) == pytest.approx(2 * math.pi * LR * LZ * H, rel=1e-12)
    assert viscosity.increment(ctx) == pytest.approx(math.sqrt(2 * viscosity_energy() / C), rel=1e-12)


def test_gent_tends_to_neo_hookean():
    ctx = make_ctx()
    ctx.u.interpolate(lambda x: np.vstack([0.2 * x[0] * (1 - x[0]), 0.5 * (1 - x[0] ** 2)]))
    nh = global_sum(fem.form(MembraneStrain(NeoHookean()).energy(ctx)))
    # W_Gent - W_NH = (I1-3)^2 / (4 Jm) + O(Jm^-2): the deviation falls like 1/Jm
    dev = [global_sum(fem.form(MembraneStrain(Gent(Jm=jm)).energy(ctx))) - nh for jm in (1e2, 1e3, 1e4)]
    assert dev[0] > dev[1] > dev[2] > 0
    assert dev[0] / dev[1] == pytest.approx(10, rel=0.02)
    assert dev[1] / dev[2] == pytest.approx(10, rel=0.002)
    assert global_sum(fem.form(MembraneStrain(Gent(Jm=math.inf)).energy(ctx))) == pytest.approx(nh, rel=1e-14)


@pytest.mark.mpi
def test_mooney_rivlin_energy_and_tractions_of_an_equibiaxial_stretch():
    """A flat membrane stretched by λ in both directions: I1 = 2λ² + λ⁻⁴, I2 = λ⁴ + 2λ⁻², and the
    tension N = 2 t (λ² − λ⁻⁴)(C1 + λ² C2)/λ² (a spherical balloon's P = 2N/(λR))."""
    lam, C1, C2, t = 1.3, 0.4, 0.15, 0.7
    ctx = make_ctx()
    ctx.u.interpolate(lambda x: np.vstack([(lam - 1) * x[0], 0 * x[0]]))
    term = MembraneStrain(MooneyRivlin(C1, C2), thickness=t)
    energy = t * (C1 * (2 * lam**2 + lam**-4 - 3) + C2 * (lam**4 + 2 * lam**-2 - 3))
    assert global_sum(fem.form(term.energy(ctx))) == pytest.approx(math.pi * energy, rel=1e-12)
    tension = 2 * t * (lam**2 - lam**-4) * (C1 + lam**2 * C2) / lam**2
    for N in term.tractions(ctx):
        assert global_sum(fem.form(ctx.kin.integral(N))) == pytest.approx(math.pi * tension, rel=1e-12)
    # C2 = 0 is neo-Hookean with mu = 2 C1
    nh = global_sum(fem.form(MembraneStrain(NeoHookean(0.8), thickness=t).energy(ctx)))
    assert global_sum(fem.form(MembraneStrain(MooneyRivlin(0.4, 0.0), thickness=t).energy(ctx))) == pytest.approx(
        nh, rel=1e-13)


@pytest.mark.parametrize("kwargs, word", [({"Jm": 0.0}, "Jm"), ({"Jm": -1.0}, "Jm"), ({"mu": -1.0}, "mu")])
def test_material_validation_names_the_parameter(kwargs, word):
    with pytest.raises(ValueError, match=word):
        Gent(**kwargs)


@pytest.mark.parametrize("kwargs, word", [({"C1": 0.0}, "C1"), ({"C2": -0.1}, "C2"), ({"C1": math.inf}, "C1")])
def test_mooney_rivlin_validation_names_the_parameter(kwargs, word):
    with pytest.raises(ValueError, match=word):
        MooneyRivlin(**kwargs)


def test_a_kinematics_without_i2_is_refused_by_mooney_rivlin():
    with pytest.raises(ValueError, match="I2"):
        MooneyRivlin().strain_energy(3.0)








# -- closed forms: terms made of terms, and the substrate under a drop -----------------------
def test_composite_terms_are_their_terms_energies():
    """OnSurface on the body's own kinematics is the term; Scaled is k times it (uniform stretch)."""
    ctx = make_ctx()
    lam = 1.3
    ctx.u.interpolate(lambda x: np.vstack([(lam - 1) * x[0], 0 * x[0]]))
    on = global_sum(fem.form(TERMS["on-surface"][1](ctx).energy(ctx)))
    scaled = global_sum(fem.form(TERMS["scaled"][1](ctx).energy(ctx)))
    assert on == pytest.approx(0.7 * math.pi * lam**2, rel=1e-12)
    assert scaled == pytest.approx(2.5 * math.pi * uniform_stretch_W(NeoHookean(), lam), rel=1e-12)


def substrate_energy(name, u, states=None):
    ctx = substrate_ctx()
    term = TERMS[name][1](ctx)
    form = fem.form(term.energy(ctx))
    ctx.u.interpolate(u)
    for state, value in (states or {}).items():
        ctx.states[state].x.array[:] = value
    return global_sum(form)


def test_linear_elasticity_of_a_homogeneous_strain():
    """u = (a R, e Z), p = K tr(eps): W = mu eps:eps + lambda/2 tr(eps)^2 over the volume pi."""
    a, e, mu, nu = 0.02, -0.03, 1.0, 0.3
    K, lam = 2 * mu * (1 + nu) / (3 * (1 - 2 * nu)), 2 * mu * nu / (1 - 2 * nu)
    tr = 2 * a + e
    got = substrate_energy("linear-elasticity", lambda x: np.vstack([a * x[0], e * x[1]]), {"solid_pressure": K * tr})
    assert got == pytest.approx(math.pi * (mu * (2 * a**2 + e**2) + 0.5 * lam * tr**2), rel=1e-12)


def test_linear_surface_tension_of_a_paraboloid():
    """u_z = c R^2 on the wetted top: (gamma/2) int (2 c R)^2 dA = pi gamma c^2 R0^4."""
    c = 0.3
    got = substrate_energy("linear-surface-tension", lambda x: np.vstack([0 * x[0], c * x[0] ** 2]))
    assert got == pytest.approx(math.pi * 0.6 * c**2 * R_DROP**4, rel=1e-12)


def test_linear_drop_loads_on_a_polynomial_displacement():
    """u = (a R, c R^2): the ring's pull, the Laplace pressure and the tangential line force,
    -2 pi R0 g sin(th) c R0^2 + (2 g sin(th)/R0) pi c R0^4 / 2 + g cos(th) 2 pi R0 a R0."""
    a, c, g = 0.04, 0.3, 0.8
    got = substrate_energy("linear-drop-loads", lambda x: np.vstack([a * x[0], c * x[0] ** 2]))
    s = math.sin(THETA)
    want = -math.pi * g * s * c * R_DROP**3 + 2 * math.pi * g * math.cos(THETA) * a * R_DROP**2
    assert got == pytest.approx(want, rel=1e-12)


def test_spherical_cap_drop_is_its_cap_and_ignores_a_rigid_lift():
    """On the flat substrate, lifted rigidly by d (the liquid's volume does not change):
    gamma_l pi R0^2 (1 + t^2) - p (pi/6 R0^3 t (3 + t^2) - V0)."""
    t, p, g, V0 = 0.45, 1.1, 0.8, 0.05
    for d in (0.0, 0.07):
        got = substrate_energy("spherical-cap-drop", lambda x: np.vstack([0 * x[0], d + 0 * x[0]]),
                               {"cap_slope": t, "drop_pressure": p})
        want = g * math.pi * R_DROP**2 * (1 + t * t) - p * (math.pi / 6 * R_DROP**3 * t * (3 + t * t) - V0)
        assert got == pytest.approx(want, rel=1e-12)


def configure(ctx, term):
    """A non-homogeneous configuration with every state the term has away from zero, and a
    perturbation of every state (the same closed-form functions on every rank count)."""
    if isinstance(ctx.kin, AxisymmetricMembrane):
        ctx.u.interpolate(lambda x: np.vstack([0.2 * x[0] * (1 - x[0]), 0.5 * (1 - x[0] ** 2)]))
        du = lambda x: np.vstack([0.6 * np.sin(3 * x[0]) * x[0], -0.4 * np.cos(2 * x[0])])  # noqa: E731
    else:
        ctx.u.interpolate(lambda x: np.vstack([0.1 * x[0] * (1 + 0.5 * (x[1] - Z0)),
                                               0.15 * (x[1] - Z0) ** 2 - 0.1 * x[1] + 0.05 * x[0] ** 2]))
        du = lambda x: np.vstack([0.5 * x[0] * np.cos(x[1]), 0.4 * np.sin(x[0] + 2 * x[1])])  # noqa: E731
    for name, value in CONSTANTS.items():
        ctx.constant(name).value = value
    if isinstance(term, Viscosity):
        term.previous.interpolate(lambda x: np.vstack([0.02 * x[0], -0.03 * x[1]]))
    perturbation = {}
    for name, state in ctx.states.items():
        d = fem.Function(state.function_space)
        if name == "displacement":
            d.interpolate(du)
        elif name in REAL_STATES:
            state.x.array[:] = REAL_STATES[name]
            d.x.array[:] = 0.7
        else:  # a field multiplier (the solid's mixed pressure)
            state.interpolate(lambda x: 0.3 + 0.2 * x[0] - 0.1 * x[1])
            d.interpolate(lambda x: 0.5 * np.sin(x[0] + 2 * x[1]))
        perturbation[name] = d
    return perturbation


def term_taylor(name, comm):
    body, factory = TERMS[name]
    ctx = BODIES[body](comm=comm)
    term = factory(ctx)
    prefix = f"bcfem_test_terms_{name.replace('-', '_')}_"
    with Problem(ctx, [term], [], prefix) as problem:
        dx = problem.vector_from(list(configure(ctx, term).values()))
        energy = fem.form(problem.lagrangian)
        try:
            return taylor(problem, lambda: global_sum(energy), dx)
        finally:
            dx.destroy()


@pytest.mark.parametrize("name", sorted(TERMS))
def test_taylor_residual_and_tangent_are_derivatives(name):
    """E(x + e dx) - E - e F.dx and F(x + e dx) - F - e J dx are O(e^2) in every state;
    on 2 ranks the numbers are those of one rank."""
    result = term_taylor(name, MPI.COMM_WORLD)
    assert_second_order(result, linear=name in LINEAR)
    if MPI.COMM_WORLD.size > 1:
        alone = term_taylor(name, MPI.COMM_SELF)
        for key in ("energy", "dE", "F", "Jdx"):
            assert result[key] == pytest.approx(alone[key], rel=1e-11, abs=1e-13), key
        for key in ("energy_remainders", "residual_remainders"):
            assert np.allclose(result[key], alone[key], rtol=1e-6, atol=1e-14), key


def test_a_wrong_residual_fails_the_taylor_test():
    """The test can fail: a residual that is not the energy's derivative gives rate 1."""
    ctx = make_ctx()
    term = SurfaceTension(0.7)
    E = term.energy(ctx)
    v = ufl.TestFunction(ctx.u.function_space)
    wrong = 1.5 * ufl.derivative(E, ctx.u, v)
    with Problem(ctx, [term], [], "bcfem_test_terms_wrong_", rows={"displacement": wrong}) as problem:
        dx = problem.vector_from(list(configure(ctx, term).values()))
        energy = fem.form(problem.lagrangian)
        result = taylor(problem, lambda: global_sum(energy), dx)
        dx.destroy()
    rates = rate(result["energy_remainders"], 1.0)
    assert np.all(np.abs(rates - 1) < 0.1), rates


@pytest.mark.mpi
def test_an_inverted_solid_is_inadmissible():
    """J <= 0 at a quadrature point makes the solid's strain energy undefined (ln J) though a
    residual in 1/J may vanish: the term vetoes such a state; a stretched one it admits."""
    ctx = solid_ctx()
    term = SolidStrain(NearlyIncompressibleNeoHookean(mu=1.0, kappa=100.0))
    term.energy(ctx)
    ctx.u.interpolate(lambda x: np.vstack([0.2 * x[0], 0.1 * x[1]]))
    assert term.inadmissible(ctx) is None
    ctx.u.interpolate(lambda x: np.vstack([0 * x[0], -1.5 * x[1]]))  # F_zz = -0.5: J < 0 everywhere
    message = term.inadmissible(ctx)
    assert message is not None and "inverts" in message
