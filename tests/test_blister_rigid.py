"""blister-rigid (clamped edge): limits, branch shape, limit points, convergence, equivalences."""

import math

from mpi4py import MPI

import numpy as np
import pytest

from bcfem.path.volume_control import VolumeControl
from bcfem.run.trace import trace
from bcfem.scenes import blister_rigid
from bcfem.solver.problem import Problem
from bcfem.theory import membrane


def branch_of(**kwargs):
    """(the scene, its branch); the branch's problem is closed."""
    params = blister_rigid.Params(**kwargs)
    scene = blister_rigid.build(params, MPI.COMM_WORLD)
    branch, problem = trace(scene)
    problem.close()
    return scene, branch


@pytest.fixture(scope="module")
def gent():
    return branch_of(material="gent", Jm=100.0, cells=100)


@pytest.fixture(scope="module")
def neo_hookean():
    return branch_of(material="neo-hookean", cells=100)


def test_gent_branch_is_n_shaped(gent):
    _, branch = gent
    kinds = [lp.kind for lp in branch.limit_points]
    assert kinds == ["max", "min"]
    vmax, vmin = (lp.values for lp in branch.limit_points)
    assert vmax["V_over_V0"] < vmin["V_over_V0"] and vmin["P"] < vmax["P"]
    assert branch.rows[-1]["V_over_V0"] == pytest.approx(6.0, abs=1e-9)
    assert branch.rows[-1]["P"] > vmin["P"]
    # volume grows monotonically along the whole branch (no fold in V)
    assert np.all(np.diff(branch.column("V_over_V0")) > 0)


def test_neo_hookean_has_one_maximum_then_decays(neo_hookean):
    _, branch = neo_hookean
    assert [lp.kind for lp in branch.limit_points] == ["max"]
    v_lp = branch.limit_points[0].values["V_over_V0"]
    V, P = branch.column("V_over_V0"), branch.column("P")
    assert np.all(np.diff(P[V > v_lp]) < 0)
    assert np.all(np.diff(P[V < v_lp]) > 0)


def volume_problem(scene):
    return Problem(scene.ctx, scene.terms, scene.bcs, scene.prefix, scene.petsc_options)


def test_limit_point_is_a_true_maximum(neo_hookean):
    """P at the located fold exceeds P at V_lp +- d by ~ |P''| d^2 / 2, equally on both sides."""
    scene, branch = neo_hookean
    lp = branch.limit_points[0].values
    problem = volume_problem(scene)
    control = VolumeControl.membrane(scene.ctx)
    d = 2e-3
    v0 = 4 * math.pi / 3
    drops = []
    for v in (lp["V_over_V0"] - d, lp["V_over_V0"] + d):
        control.solve_to(problem, v * v0)
        drops.append(lp["P"] - scene.observe()["P"])
    assert min(drops) > 0
    assert drops[0] / drops[1] == pytest.approx(1.0, abs=0.05)  # symmetric: the fold is centred to ~1e-4 d


def test_volume_control_equals_arc_length(gent):
    scene, branch = gent
    problem = volume_problem(scene)
    control = VolumeControl.membrane(scene.ctx)
    v0 = 4 * math.pi / 3
    rows = branch.rows[1::4]
    for row in rows:
        control.solve_to(problem, row["V_over_V0"] * v0)
        values = scene.observe()
        assert values["V_over_V0"] == pytest.approx(row["V_over_V0"], rel=1e-11)
        assert values["P"] == pytest.approx(row["P"], rel=1e-8)
        assert values["aspect"] == pytest.approx(row["aspect"], rel=1e-8)


def test_small_volume_limit_is_foppl_hencky():
    """P / P_Föppl -> 1 as V -> 0 (the exact small-deflection limit, not eq. 3.17)."""
    params = blister_rigid.Params(material="neo-hookean", cells=200, degree=2, v_start=0.002)
    scene = blister_rigid.build(params, MPI.COMM_WORLD)
    problem = volume_problem(scene)
    control = VolumeControl.membrane(scene.ctx)
    scene.start()
    v0 = 4 * math.pi / 3
    volumes = [0.08, 0.04, 0.02, 0.01, 0.005]
    deviation = []
    for v in volumes:
        control.solve_to(problem, v * v0)
        P = scene.observe()["P"]
        deviation.append(abs(P / membrane.foppl_pressure(v) - 1))
    deviation = np.array(deviation)
    assert np.all(np.diff(deviation) < 0)
    # the geometric/material correction is O(V^2): halving V divides it by 4
    assert np.log2(deviation[:-1] / deviation[1:])[-1] == pytest.approx(2.0, abs=0.1)
    assert deviation[-1] < 1e-3


def test_simple_membrane_is_the_ritz_minimiser():
    """Eq. 3.17 is the minimiser of the Föppl energy over w = h(1-r^2), u = c r(1-r)."""
    from scipy.integrate import quad
    from scipy.optimize import minimize

    P, nu = 0.37, 0.5
    E = 3.0  # E = 2 mu (1 + nu) with mu = 1

    def energy(hc):
        h, c = hc

        def density(x):
            er = c * (1 - 2 * x) + 2 * h * h * x * x
            et = c * (1 - x)
            return (er**2 + et**2 + 2 * nu * er * et) * x

        U = 0.5 * E / (1 - nu**2) * 2 * math.pi * quad(density, 0, 1, epsabs=1e-14)[0]
        return U - P * math.pi * h / 2

    res = minimize(energy, [0.3, 0.05], method="Nelder-Mead",
                   options={"xatol": 1e-12, "fatol": 1e-16, "maxiter": 20000})
    assert res.x[0] == pytest.approx(float(membrane.simple_membrane_deflection(P)), rel=1e-6)


def test_hencky_constant_matches_the_classical_value():
    """w0 = K(nu) a (p a / E t)^(1/3); Hencky's exact K(0.3) = 0.653 (Timoshenko &
    Woinowsky-Krieger, sec. 97; their Ritz value is 0.662)."""
    _, I1, _ = membrane.foppl_constants(0.3)
    assert I1 == pytest.approx(0.653, abs=1e-3)
    # and the exact limit is softer than the one-term Ritz solution of eq. 3.17
    assert membrane.foppl_to_simple_ratio() == pytest.approx(0.96993, abs=1e-5)


def droplet_deviation(stiffness, alpha=1.0):
    scene, branch = branch_of(material="neo-hookean", alpha=alpha, stiffness=stiffness, cells=100,
                              v_max=1.5, v_start=0.05)
    deviation = 0.0
    for row in branch.rows[1:]:
        theta = membrane.droplet_angle_from_volume(row["V_over_V0"])
        p_exact, aspect_exact, _ = membrane.droplet(theta)
        deviation = max(deviation, abs(row["P"] / alpha / p_exact - 1), abs(row["aspect"] / aspect_exact - 1),
                        abs(math.radians(row["contact_angle_deg"]) / theta - 1))
    return deviation, branch


def test_droplet_limit():
    """mu_f t0 / gamma_l -> 0: the spherical cap of eq. 3.86 (with sin^3 in V/V0), within 1e-4."""
    deviation, branch = droplet_deviation(1e-5)
    assert deviation < 1e-4
    # the droplet's pressure peaks at the hemisphere: V/V0 = 1/2, dp R0 / gamma = 2
    (lp,) = branch.limit_points
    assert lp.kind == "max"
    assert lp.values["V_over_V0"] == pytest.approx(0.5, rel=1e-4)
    assert lp.values["P"] == pytest.approx(2.0, rel=1e-4)
    # and the membrane's contribution vanishes linearly with its stiffness
    coarse, _ = droplet_deviation(1e-4)
    assert coarse / deviation == pytest.approx(10.0, rel=0.05)


@pytest.mark.parametrize("degrees", [30, 60, 90, 120, 150])
def test_droplet_volume_is_the_spherical_cap(degrees):
    """The droplet limit's V/V0 is the cap's volume over the hemisphere's, for any angle (eq. 3.86
    as printed, with sin(phi0) instead of sin^3 in the denominator, agrees at 90 degrees only)."""
    theta = math.radians(degrees)
    cap = math.pi * (1 - math.cos(theta)) ** 2 * (2 + math.cos(theta)) / (3 * math.sin(theta) ** 3) / (4 * math.pi / 3)
    assert float(membrane.droplet(theta)[2]) == pytest.approx(cap, rel=1e-14)


@pytest.mark.convergence
@pytest.mark.parametrize("degree, rate", [(1, 2.0), (2, 4.0)])
def test_limit_point_pressure_converges_at_2k(degree, rate):
    """The fold pressure is an energy-like functional: error O(h^(2k))."""
    cells = [20, 40, 80, 160] if degree == 1 else [10, 20, 40, 80]
    p_max = []
    for n in cells:
        _, branch = branch_of(material="gent", Jm=100.0, cells=n, degree=degree, v_max=1.5)
        p_max.append(branch.limit_points[0].values["P"])
    d = np.abs(np.diff(p_max))
    observed = np.log2(d[:-1] / d[1:])
    assert observed[-1] == pytest.approx(rate, abs=0.25), observed
