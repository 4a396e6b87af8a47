"""droplet-soft (ch. 5): the wetting ridge under a sessile drop, linear and neo-Hookean.

* the terms: closed forms (a cap's volume above a lifted and a dented surface, the ring
  loads, homogeneous small strain) and Taylor tests of the residual;
* the linear FE surface against the Hankel solutions of ``bcfem.theory.ridge`` (half-space
  and layer), and their convergence under refinement at an observed rate;
* the neo-Hookean model: the rigid limit (Young's angle, the spherical cap, the linear ridge)
  and Neumann's triangle at the tip for large γ/(μ R0);
* the command line: bad input exits 2 before meshing; 2 ranks give the serial numbers.
"""

import json
import math

from mpi4py import MPI

import numpy as np
import pytest
from dolfinx import fem
from helpers import bcfem, refused

from bcfem.geometry.substrate import WETTED, SubstrateGeometry, create_mesh
from bcfem.mpi import global_sum
from bcfem.physics.context import Context
from bcfem.physics.linear_solid import LinearDropLoads, LinearElasticity, SubstrateKinematics
from bcfem.physics.sessile_drop import SphericalCapDrop, cap_volume
from bcfem.scenes import droplet_soft as ds
from bcfem.solver.problem import Problem
from bcfem.theory import ridge

COARSE = {"size_contact": 0.01}


def solve(**kwargs):
    return ds.solve(ds.Params(**kwargs), MPI.COMM_WORLD)


# -- the terms --------------------------------------------------------------------------------
def substrate_ctx(comm=MPI.COMM_WORLD):
    """A coarse block 3 R0 wide and deep, P2, with the kinematics of the droplet scene."""
    data = create_mesh(SubstrateGeometry(size_factor=3.0, size_contact=0.05, size_far=0.5), comm)
    V = fem.functionspace(data.mesh, ("Lagrange", 2, (2,)))
    u = fem.Function(V)
    return Context(u, SubstrateKinematics(u, quadrature_degree=5, facet_tags=data.facet_tags))


@pytest.mark.mpi
@pytest.mark.parametrize("lift, dent, stretch", [(0.3, 0.0, 0.0), (0.0, 0.2, 0.0), (0.1, -0.15, 0.07)])
def test_cap_drop_energy_in_closed_form(lift, dent, stretch):
    """u = (a R, c + d R²) on the top: the contact circle moves to r = 1 + a, z = c + d; the
    liquid holds the cap above it plus what the dent holds below, V = cap + π d r_c^2/2
    (the surface z = c + d R² under a flat plane at z_c: ∫ d (1 - R²) 2π r dr, r = (1 + a) R)."""
    ctx = substrate_ctx()
    gamma, v0, t, p = 0.7, 0.9, 0.6, 1.3
    form = fem.form(SphericalCapDrop(gamma, v0, 1.0, WETTED).energy(ctx))
    ctx.real_state("cap_slope").x.array[:] = t
    ctx.real_state("drop_pressure").x.array[:] = p
    ctx.u.interpolate(lambda x: np.vstack([stretch * x[0], lift + dent * x[0] ** 2 * (1 + 0 * x[1])]))
    rc = 1 + stretch
    volume = cap_volume(rc, 2 * math.atan(t)) + math.pi * dent * rc**2 / 2
    area = math.pi * rc**2 * (1 + t * t)
    assert global_sum(form) == pytest.approx(gamma * area - p * (volume - v0), rel=1e-12)


@pytest.mark.mpi
def test_linear_terms_in_closed_form():
    """Ring loads: 2π R0 u(R0) exactly; the Laplace pressure on u_z = d R² is π R0² d/2 Δp.
    Elasticity: u = (a R, b Z) is a uniform strain diag(a, b, a), W = μ ε:ε + λ/2 (tr ε)²."""
    ctx = substrate_ctx()
    theta, gamma, pull = 1.1, 0.4, 0.3
    loads = fem.form(LinearDropLoads(gamma, theta, 1.0, WETTED, pull).energy(ctx))
    d, a = 0.2, 0.05
    ctx.u.interpolate(lambda x: np.vstack([a * x[0], d * x[0] ** 2]))
    s = gamma * math.sin(theta)
    expected = -s * 2 * math.pi * d + 2 * s * math.pi * d / 2 + gamma * pull * 2 * math.pi * a
    assert global_sum(loads) == pytest.approx(expected, rel=1e-12)

    nu, a, b = 0.3, 0.02, -0.03
    elastic = LinearElasticity(nu=nu)
    form = fem.form(elastic.energy(ctx))
    ctx.u.interpolate(lambda x: np.vstack([a * x[0], b * x[1]]))
    lam = 2 * nu / (1 - 2 * nu)
    ctx.states["solid_pressure"].x.array[:] = (2 * a + b) / elastic.compliance
    W = (2 * a * a + b * b) + lam / 2 * (2 * a + b) ** 2
    assert global_sum(form) == pytest.approx(W * math.pi * 9 * 3, rel=1e-11)


@pytest.mark.mpi
@pytest.mark.parametrize("model", ["linear", "neo-hookean"])
def test_residual_is_the_derivative_of_the_energy(model):
    """Taylor remainders |E(x + e dx) - E(x) - e F(x).dx| fall like e² (ratio 4 per halving)."""
    scene = ds.build(ds.Params(model=model, gamma_s=0.3, gamma_l=0.5, gamma_ls=0.6, nu=0.2,
                               size_contact=0.05, width=3), MPI.COMM_WORLD)
    energy = fem.form(sum(term.energy(scene.ctx) for term in scene.terms))
    with Problem(scene.ctx, scene.terms, [], "bcfem_test_droplet_taylor_") as problem:
        # smooth fields (u_r = 0 on the axis, as the hoop stretch u_r/R needs), random scalars
        rng = np.random.default_rng(problem.comm.rank)

        def fill(scale, seed):
            for name, state in zip(problem.names, problem.states):
                if name == "displacement":
                    state.interpolate(lambda x: scale * np.vstack([x[0] * np.sin(3 * x[1] + seed),
                                                                   np.cos(2 * x[0] + seed)]))
                else:
                    state.x.array[:] = scale * (1 + rng.standard_normal(state.x.array.size))
                    state.x.scatter_forward()
            return problem.vector_from(problem.states)

        dx = fill(2e-3, 1.0)
        x0 = fill(1e-2, 0.0)
        f0, x = x0.duplicate(), x0.duplicate()
        problem.snes.computeFunction(x0, f0)
        problem.functions_from(x0, problem.states)
        E0, slope = global_sum(energy), f0.dot(dx)
        remainders = []
        for k in range(4):
            eps = 0.5**k
            x.waxpy(eps, dx, x0)
            problem.functions_from(x, problem.states)
            remainders.append(abs(global_sum(energy) - E0 - eps * slope))
        for v in (x0, dx, f0, x):
            v.destroy()
    ratios = np.array(remainders[:-1]) / np.array(remainders[1:])
    assert np.all(np.abs(ratios - 4) < 0.3), (remainders, ratios)


# -- the linear model against the Hankel solutions --------------------------------------------
@pytest.mark.mpi
def test_linear_half_space_matches_the_hankel_solution():
    scene, rows, summary = solve(gamma_s=0.1, gamma_l=0.1, gamma_ls=0.1, width=40, **COARSE)
    assert summary["status"] == "ok" and rows[-1]["newton_iterations"] == 1
    assert abs(summary["ridge_height_error"]) < 1e-3
    # the whole surface: u_r and u_z within 2e-3 of the ridge height
    profile = [row for row in scene.profile if 0 < row["R_over_R0"] <= 3 and row["R_over_R0"] != 1.0]
    radii = np.array([row["R_over_R0"] for row in profile])
    exact = ridge.surface_displacement(radii, 20.0, 0.5)
    scale = summary["ridge_height"]
    assert np.max(np.abs([row["u_z"] for row in profile] - 0.1 * exact.u_z)) < 2e-3 * scale
    assert np.max(np.abs([row["u_r"] for row in profile] - 0.1 * exact.u_r)) < 5e-3 * scale


@pytest.mark.mpi
def test_linear_layer_matches_the_hankel_solution():
    """ν = 0.3, c = 10, r0/h = 2 (Fig. 5.5's parameters)."""
    _, _, summary = solve(gamma_s=1 / 7, gamma_l=0.1, gamma_ls=1 / 7, nu=0.3, thickness=0.5, width=6, **COARSE)
    assert summary["c"] == pytest.approx(10.0)
    assert abs(summary["ridge_height_error"]) < 1e-3


def observed_rates(errors):
    errors = np.abs(errors)
    return np.log2(errors[:-1] / errors[1:])


@pytest.mark.convergence
@pytest.mark.parametrize("case", [
    {"width": 80},  # a half-space: the block's finite size shifts u_z(r0) by about 0.7 (R0/L)^3
    {"thickness": 0.5, "width": 10, "nu": 0.3, "gamma_s": 1 / 7, "gamma_ls": 1 / 7}])
def test_linear_ridge_height_converges(case):
    """Halving every element size (refine) divides the ridge height's error by about 5."""
    params = {"gamma_s": 0.1, "gamma_l": 0.1, "gamma_ls": 0.1, "size_contact": 0.01, **case}
    errors = [solve(refine=k, **params)[2]["ridge_height_error"] for k in range(3)]
    rates = observed_rates(errors)
    print(f"ridge-height errors {errors}, observed rates {rates}")
    assert np.all(rates > 1.8), (errors, rates)
    assert abs(errors[-1]) < 3e-5


# -- the neo-Hookean model --------------------------------------------------------------------
@pytest.mark.mpi
def test_rigid_limit_gives_young_and_the_linear_ridge():
    """Young's angle 60°: as the tensions fall from 1e-3 to 1e-4 μ R0 the cap's angle tends to
    Young's (its deviation, from the volume the dent under the drop takes, falls tenfold), its
    contact circle to R0; the cap stays spherical (Laplace); and the ridge is the linear one
    (balanced contact force, the model's linearisation) to within the tip's nonlinearity."""
    found = {}
    for scale in (1e-3, 1e-4):
        tensions = {"gamma_s": 1.5 * scale, "gamma_l": scale, "gamma_ls": scale}
        _, _, nh = solve(model="neo-hookean", load_step=0.5, **tensions, **COARSE)
        found[scale] = nh
        assert nh["young_angle_deg"] == pytest.approx(60.0)
        assert nh["cap_angle_deg"] == pytest.approx(60.0, abs=200 * scale)
        assert nh["tip_r"] == pytest.approx(1.0, abs=0.1 * scale)
        # the Laplace pressure of the spherical cap on the moved contact circle
        assert nh["laplace_pressure"] == pytest.approx(
            2 * math.sin(math.radians(nh["cap_angle_deg"])) / nh["tip_r"], rel=1e-8)
        _, _, linear = solve(contact_force="balanced", **tensions, **COARSE)
        assert nh["ridge_height"] == pytest.approx(linear["ridge_height"], rel=0.03)
    ratio = (60 - found[1e-3]["cap_angle_deg"]) / (60 - found[1e-4]["cap_angle_deg"])
    assert 8 < ratio < 12


@pytest.mark.slow
@pytest.mark.parametrize("tensions", [(1.0, 1.0, 1.0), (0.8, 1.0, 0.5)])
def test_neumann_triangle_at_the_tip(tensions):
    """γ/(μ R0) of order 1 on a layer r0/h = 2: the tip's wedges approach Neumann's triangle
    (120° each for equal tensions), better on the finer mesh."""
    gamma_s, gamma_l, gamma_ls = tensions
    found = []
    for refine in (0, 1):
        _, _, summary = solve(model="neo-hookean", gamma_s=gamma_s, gamma_l=gamma_l, gamma_ls=gamma_ls,
                              thickness=0.5, width=6, size_contact=0.004, refine=refine, load_step=0.1)
        assert summary["status"] == "ok"
        found.append(summary)
    neumann = found[-1]["neumann_angles_deg"]
    assert found[1]["neumann_residual"] < found[0]["neumann_residual"] < 0.03
    for phase in ("solid", "liquid", "vapour"):
        key = "cusp_angle_deg" if phase == "solid" else f"{phase}_angle_deg"
        assert found[-1][key] == pytest.approx(neumann[phase], abs=1.5)


@pytest.mark.slow
def test_table_5_1_water_at_young_reaches_neumann():
    """Table 5.1's water/PDMS (72, 59, 16 mN/m, E = 16 kPa, R0 = 1 mm, h = 50 um), whose
    triangle is nearly degenerate (Neumann's cusp 40°): with the drop at rest at Young's angle
    (53.3°) the tip's wedge goes to Neumann's as the mesh is refined; at the printed 108.1° it
    does not (``benchmarks/droplet_soft_cusp.py``)."""
    mu_r0 = 16e3 / 3 * 1e-3 * 1e3  # mN/m
    params = {"model": "neo-hookean", "gamma_l": 72 / mu_r0, "gamma_s": 59 / mu_r0, "gamma_ls": 16 / mu_r0,
              "thickness": 0.05, "width": 3.0, "size_contact": 1.5e-4, "load_step": 0.1}
    found = [solve(refine=k, **params)[2] for k in (0, 1)]
    neumann = found[0]["neumann_angles_deg"]["solid"]
    assert neumann == pytest.approx(39.97, abs=0.01)
    assert found[1]["neumann_residual"] < found[0]["neumann_residual"] < 0.02
    assert abs(found[1]["cusp_angle_deg"] - neumann) < abs(found[0]["cusp_angle_deg"] - neumann)
    assert found[1]["cusp_angle_deg"] == pytest.approx(neumann, abs=1.0)


NEUMANN_CASE = {"model": "neo-hookean", "gamma_s": 0.2, "gamma_l": 0.2, "gamma_ls": 0.15, "size_contact": 0.02,
                "width": 4, "load_step": 0.5}


def rest_angle_of(volume):
    """The angle (degrees) of the cap on the unit circle holding ``volume``: π/6 t(3 + t²) = V."""
    roots = np.roots([1.0, 0.0, 3.0, -6.0 * volume / math.pi])
    t = float(roots[np.argmin(abs(roots.imag))].real)
    return math.degrees(2 * math.atan(t))


@pytest.mark.mpi
def test_neumann_control_is_the_volume_control_at_its_volume():
    """--control neumann (the dissertation's iteration): the drop's volume becomes the output at
    which the liquid pulls along the resultant of the solid tensions at the tip (misfit 0), its
    angle φl and Laplace pressure those of the spherical cap; and the volume control at that
    volume is the same equilibrium (same φl, tip and misfit), from its own load path."""
    _, _, held = solve(control="neumann", **NEUMANN_CASE)
    _, _, fixed = solve(**NEUMANN_CASE)
    assert held["status"] == "ok" and held["control"] == "neumann"
    assert abs(held["neumann_misfit"]) < 1e-8
    assert abs(fixed["neumann_misfit"]) > 1e-3  # the rest cap on R0 does not meet it
    assert held["drop_volume"] != pytest.approx(held["rest_volume"], rel=1e-2)
    assert held["laplace_pressure"] == pytest.approx(
        2 * math.sin(math.radians(held["cap_angle_deg"])) / held["tip_r"], rel=1e-8)
    _, _, same = solve(cap_angle=rest_angle_of(held["drop_volume"]), **NEUMANN_CASE)
    assert same["drop_volume"] == pytest.approx(held["drop_volume"], rel=1e-12)
    for key in ("cap_angle_deg", "tip_r", "tip_z", "ridge_height"):
        assert same[key] == pytest.approx(held[key], rel=1e-6), key
    assert abs(same["neumann_misfit"]) < 1e-6


# -- the command line -------------------------------------------------------------------------
@pytest.mark.serial
@pytest.mark.parametrize("args, word", [
    (["--gamma-s", "-0.1"], "gamma-s"), (["--gamma-ls", "-1"], "gamma-ls"), (["--gamma-l", "0"], "gamma-l"),
    (["--nu", "0.6"], "nu"), (["--nu", "-1"], "nu"), (["--thickness", "-0.5"], "thickness"),
    (["--gamma-s", "0.5", "--gamma-ls", "0.1", "--gamma-l", "0.1"], "Young"),
    (["--model", "neo-hookean", "--gamma-l", "1", "--gamma-s", "0.3", "--gamma-ls", "0.3"], "Neumann"),
    (["--control", "neumann"], "control"), (["--model", "neo-hookean", "--control", "mass"], "control")])
def test_bad_input_exits_2_before_meshing(tmp_path, args, word):
    out = tmp_path / "out"
    assert word in refused("run", "droplet-soft", *args, out=out)
    assert not out.exists()


@pytest.mark.serial
@pytest.mark.parametrize("model, control", [("linear", "volume"), ("neo-hookean", "volume"),
                                            ("neo-hookean", "neumann")])
def test_two_ranks_give_the_serial_numbers(tmp_path, model, control):
    args = ["run", "droplet-soft", "--model", model, "--gamma-s", "0.2", "--gamma-l", "0.2", "--gamma-ls", "0.15",
            "--size-contact", "0.02", "--width", "4", "--load-step", "0.5", "--control", control, "--quiet"]
    summaries = []
    for ranks in (1, 2):
        out = tmp_path / f"n{ranks}"
        done = bcfem(*args, "--out", out, ranks=ranks)
        assert done.returncode == 0, done.stderr
        summaries.append(json.loads((out / "summary.json").read_text()))
        assert (out / "profile.csv").exists() and (out / "profile.png").exists()
    serial, parallel = summaries
    assert parallel["ranks"] == 2
    for key in ("ridge_height", "cusp_angle_deg", "cap_angle_deg", "laplace_pressure", "drop_volume"):
        if serial[key] is None:  # the linear model has no drop volume
            assert parallel[key] is None, key
            continue
        assert parallel[key] == pytest.approx(serial[key], rel=1e-8, abs=1e-12), key
