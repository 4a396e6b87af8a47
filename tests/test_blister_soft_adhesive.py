"""Scene ``blister-soft --edge adhesive``: the debond radius R1 as a state on a fixed mesh.

* the mapped reference configuration in closed form, and the standard battery (Taylor rates
  of residual and tangent, R1 included; 2 ranks equal COMM_SELF, marker ``mpi``);
* the rigid limit: the onset approaches ``blister-rigid --edge adhesive`` with adhesion
  gamma_ls - dgamma, ten times closer at ten times the stiffness, for gamma_ls - dgamma = 0
  and 2.5, and does not depend on dgamma itself (slow);
* the onset two ways: the configurational force's sign change equals the zero of
  dF/dR1 at fixed V from the energies of two held models (slow);
* the dissertation's fixed-R1 model's critical point lies on the propagating branch (slow);
* ``mpirun -n 2`` equals serial through delamination (slow);
* an inverting substrate stops the run with a clear message;
* Fig. 4.8's parameters from the default --v-start: the scene chooses the start (slow).
"""

import json
import math

from mpi4py import MPI

import numpy as np
import pytest
import ufl
from dolfinx import fem
from helpers import bcfem, refused, same_loads
from soft_blister import SMALL, W, assert_battery, taylor_of

from bcfem import global_sum
from bcfem.io import read_csv
from bcfem.scenes import blister_soft

pytestmark = pytest.mark.mpi

L = 3.0
ADHESIVE = dict(SMALL, edge="adhesive", size_factor=L)


def adhesive_model(comm=MPI.COMM_WORLD, radius=1.2):
    from bcfem.scenes.blister_soft.model import Model

    model = Model(blister_soft.Params(**ADHESIVE), comm)
    model.ctx.states["debond_radius"].x.array[:] = radius
    return model


def test_mapped_reference_in_closed_form():
    """Debonded to R1 = 1.2 and stretched homogeneously about the material points, x = (1+a) X:
    every strain energy is that of the stretch over the material regions (the free membrane
    over R < R1, the bonded one over R1 < R < L, the whole block), and the interfaces' areas
    are the current ones."""
    R1, a = 1.2, 0.07
    model = adhesive_model(radius=R1)
    solid = model.ctx.kin
    V = model.u.function_space
    stretched = fem.Expression((1 + a) * solid.X - solid.x, V.element.interpolation_points)
    model.u.interpolate(stretched)
    got = {t.name: global_sum(model.form(t.energy(model.ctx))) for t in model.terms}
    k, f = SMALL["stiffness_ratio"], 1 + a
    solid_energy = k * (0.5 * (3 * f**2 - 3) - math.log(f**3)) * math.pi * L**2 * L
    want = {"stiffness_ratio*solid_strain": solid_energy,
            "membrane_strain@free": math.pi * R1**2 * W(f),
            "membrane_strain@bonded": math.pi * (L**2 - R1**2) * W(f),
            "pressure_volume@liquid": 0.0,
            "gamma_l@gamma_l": SMALL["alpha"] * math.pi * (f * R1) ** 2,
            "gamma_ls@gamma_ls": SMALL["gamma_ls"] * math.pi * (f * R1) ** 2,
            "delta_gamma@delta_gamma": SMALL["delta_gamma"] * math.pi * (L**2 - R1**2) * f**2}
    assert got == pytest.approx(want, rel=1e-11, abs=1e-12)
    # the material radius at the contact vertex is R1, at the axis and the far side unchanged
    X = fem.Function(V)
    X.interpolate(fem.Expression(solid.X, V.element.interpolation_points))
    for point, radius in (([1.0, 0.0], R1), ([0.0, 0.0], 0.0), ([L, -L], L)):
        dofs = fem.locate_dofs_geometrical(V, lambda x, p=point: np.isclose(x[0], p[0]) & np.isclose(x[1], p[1]))
        local = X.x.array.reshape(-1, 2)[dofs[dofs < V.dofmap.index_map.size_local], 0]
        found = MPI.COMM_WORLD.allgather(local.tolist())
        assert [v for part in found for v in part] == pytest.approx([radius], abs=1e-14)


def taylor_at_a_debonded_blister(comm):
    """At a debonded (R1 = 1.15), inflated, off-equilibrium state, the front free, along a
    direction that moves the front too."""
    model = adhesive_model(comm, radius=1.15)
    model.front.value = 1.0
    model.cap_guess(0.4)
    model.u.interpolate(lambda x: np.vstack([0.15 * np.clip(x[0], 0, 1.0) * (L - x[0]) / L * (x[1] + L) / L,
                                             0.1 * np.cos(x[0]) * (x[1] + L) / L]))
    model.ctx.states["solid_pressure"].interpolate(lambda x: 0.2 + 0.1 * x[0])
    model.ctx.real_state("pressure").x.array[:] = 1.5
    return taylor_of(model, f"bcfem_test_adhesive_{comm.size}_", extra={"debond_radius": 0.5})


def test_taylor_rates_and_ranks_with_a_moving_front():
    """Residual = derivative of the energy, tangent = its derivative, R1 included (rates 2);
    on 2 ranks the numbers of one."""
    assert_battery(taylor_at_a_debonded_blister)


def test_the_release_rate_is_the_energy_derivative():
    """dPi/dR1 at fixed positions (the observable) is the derivative of the assembled energy
    in R1 (central difference, error O(h^2))."""
    model = adhesive_model(radius=1.1)
    model.cap_guess(0.4)
    model.ctx.real_state("pressure").x.array[:] = 1.0
    energy = model.form(sum(t.energy(model.ctx) for t in model.terms))
    R1 = model.ctx.states["debond_radius"]
    one = fem.Function(R1.function_space)
    one.x.array[:] = 1.0
    rate = global_sum(model.form(ufl.derivative(sum(t.energy(model.ctx) for t in model.terms), R1, one)))
    differences = []
    for h in (1e-3, 5e-4):
        R1.x.array[:] = 1.1 + h
        up = global_sum(energy)
        R1.x.array[:] = 1.1 - h
        differences.append((up - global_sum(energy)) / (2 * h) - rate)
    assert abs(rate) > 1e-2
    assert abs(differences[1]) < 1e-6 * abs(rate) or abs(differences[1]) < abs(differences[0]) / 3, differences


def run(tmp_path, name, *args, ranks=1):
    out = tmp_path / name
    result = bcfem("run", *args, "--out", out, ranks=ranks)
    assert result.returncode == 0, result.stderr[-3000:]
    return json.loads((out / "summary.json").read_text()), out


@pytest.mark.slow
@pytest.mark.serial
def test_onset_tends_to_the_rigid_adhesive_edge(tmp_path):
    """Stiffness ratios 1e2, 1e3 and 1e4: the onset's V/V0 and P approach blister-rigid's
    adhesive edge with adhesion gamma_ls - dgamma (= 0 here, gamma_l = 0.5), about ten times
    closer per decade, and each branch goes on past the onset."""
    rigid, _ = run(tmp_path, "rigid", "blister-rigid", "--material", "neo-hookean", "--edge", "adhesive",
                   "--alpha", "0.5", "--adhesion", "0", "--v-max", "0.3")
    ref = rigid["delamination_onset"]
    errors = []
    for ratio in (1e2, 1e3, 1e4):
        soft, _ = run(tmp_path, f"soft{ratio:g}", "blister-soft", "--edge", "adhesive", "--stiffness-ratio", ratio,
                      "--v-max", "0.3")
        onset = soft["delamination_onset"]
        assert soft["status"] == "ok" and soft["steps"] > 10
        errors.append((abs(onset["V_over_V0"] - ref["V_over_V0"]), abs(onset["P"] / ref["P"] - 1)))
    print("onset errors (V, P) at ratios 1e2, 1e3, 1e4:", errors)
    assert errors[2][0] < 5e-5 and errors[2][1] < 3e-4, errors
    for coarse, fine in zip(errors[:-1], errors[1:]):
        assert fine[0] < coarse[0] / 5 and fine[1] < coarse[1] / 5, errors


def onset_of(scene) -> dict:
    from bcfem.run.trace import branch_of

    (event,) = branch_of(scene).events
    return event


@pytest.mark.slow
@pytest.mark.serial
@pytest.mark.parametrize("gamma_ls, delta_gamma, v_max", [(3.0, 0.5, 3.2), (0.5, 0.5, 0.3)])
def test_rigid_limit_of_the_onset_for_any_interface_energies(gamma_ls, delta_gamma, v_max):
    """On a rigid substrate only the difference gamma_ls - dgamma of the two interface energies the
    front trades costs energy (the areas under them sum to the block's top). The onset at ratios
    1e3, 1e4, 1e5 approaches blister-rigid's with adhesion gamma_ls - dgamma (the error falls by
    at least 5 per decade, O(1/ratio)) to better than 1e-3 at 1e5, on Fig. 3.14's difference 2.5
    (onset V/V0 = 3.064, where the release rate is flat in V) and on 0; and at 1e5 shifting both
    energies by 2 leaves it (to the O(gamma/ratio) the substrate's own surface stress moves it)."""
    from bcfem.run.trace import branch_of
    from bcfem.scenes import blister_rigid

    rigid = branch_of(blister_rigid.build(blister_rigid.Params(
        material="neo-hookean", alpha=0.5, edge="adhesive", adhesion=gamma_ls - delta_gamma, v_max=v_max),
        MPI.COMM_SELF)).events[0]

    def soft(ratio, shift=0.0):
        params = blister_soft.Params(edge="adhesive", stiffness_ratio=ratio, alpha=0.5, gamma_ls=gamma_ls + shift,
                                     delta_gamma=delta_gamma + shift, v_max=v_max)
        return onset_of(blister_soft.build(params, MPI.COMM_SELF))

    onsets = [soft(ratio) for ratio in (1e3, 1e4, 1e5)]
    errors = [abs(o["V_over_V0"] - rigid["V_over_V0"]) for o in onsets]
    print(f"gamma_ls - dgamma = {gamma_ls - delta_gamma}: rigid onset {rigid['V_over_V0']:.6f}; soft at 1e3, 1e4, "
          f"1e5: {[round(o['V_over_V0'], 6) for o in onsets]}, errors {errors}, "
          f"rates {[math.log10(a / b) for a, b in zip(errors, errors[1:])]}")
    assert errors[2] < 1e-3, errors
    assert errors[1] < errors[0] / 5 and errors[2] < errors[1] / 5, errors
    assert onsets[2]["P"] == pytest.approx(rigid["P"], rel=1e-3)
    shifted = soft(1e5, shift=2.0)
    assert shifted["V_over_V0"] == pytest.approx(onsets[2]["V_over_V0"], abs=1e-5)


@pytest.mark.slow
@pytest.mark.serial
def test_onset_by_configurational_force_equals_energy_comparison():
    """At stiffness ratio 100: the V/V0 where -dPi/dR1 turns positive (the scene's switch) and
    the zero of dF/dR1|_V by energies of models held at R1 = 1 +- delta agree to O(delta^2)."""
    from bcfem.run.trace import branch_of
    from bcfem.scenes.blister_soft.model import build
    from bcfem.scenes.blister_soft.onset import onset_by_energy

    scene = build(blister_soft.Params(edge="adhesive", stiffness_ratio=100.0, v_max=0.3), MPI.COMM_SELF)
    (event,) = branch_of(scene).events
    found = onset_by_energy(scene, (0.98 * event["V_over_V0"], 1.02 * event["V_over_V0"]))
    print("onset: switch", event["V_over_V0"], "energy", found)
    assert found["V_over_V0"] == pytest.approx(event["V_over_V0"], rel=1e-5)


@pytest.mark.slow
@pytest.mark.serial
def test_fixed_front_critical_point_lies_on_the_propagating_branch():
    """Fig. 4.8's method: a model held at R1 = 1.2 R0 traced until its release rate reaches
    zero is the propagating branch's state at R1 = 1.2 (stiffness ratio 2, Fig. 4.5's tensions)."""
    from bcfem.run.trace import branch_of
    from bcfem.scenes.blister_soft.model import build
    from bcfem.scenes.blister_soft.onset import critical_point

    params = blister_soft.Params(edge="adhesive", stiffness_ratio=2.0, v_max=1.0)
    scene = build(params, MPI.COMM_SELF)
    scene.end = lambda values: values["R1_over_R0"] - 1.2
    propagating = branch_of(scene).rows[-1]
    held = critical_point(scene, 1.2)
    assert propagating["R1_over_R0"] == pytest.approx(1.2, abs=1e-6)
    for key in ("V_over_V0", "P", "r1_over_R0", "indentation"):
        assert held[key] == pytest.approx(propagating[key], rel=1e-5), key


@pytest.mark.slow
@pytest.mark.serial
def test_two_ranks_equal_serial_through_delamination(tmp_path):
    args = ("blister-soft", "--edge", "adhesive", "--stiffness-ratio", "2", "--v-max", "0.6", "--growth", "1.5",
            "--size-contact", "0.02")
    serial, out1 = run(tmp_path, "serial", *args)
    parallel, out2 = run(tmp_path, "parallel", *args, ranks=2)
    assert parallel["ranks"] == 2
    for key in ("V_over_V0", "P", "r1_over_R0"):
        assert parallel["delamination_onset"][key] == pytest.approx(serial["delamination_onset"][key], rel=1e-7)
    # the rows at the same arc length, and the end V/V0 = 0.6, which the steps do not decide
    rows1, rows2 = read_csv(out1 / "branch.csv"), read_csv(out2 / "branch.csv")
    assert rows1[-1]["R1_over_R0"] > 1.05
    pairs = same_loads(rows2, rows1, "s") + [(rows2[-1], rows1[-1])]
    assert pairs[0][0] is rows2[0]
    for mine, theirs in pairs:
        assert mine == pytest.approx(theirs, rel=1e-7, abs=1e-9)


@pytest.mark.serial
def test_an_inverting_substrate_fails_with_a_clear_message(tmp_path):
    """Fig. 4.8's tensions (dgamma = 0) at stiffness ratio 2 on the grading-only mesh (no
    --size-wetted): the homotopy from the stiff start at V/V0 = 0.05 reaches a state whose
    substrate inverts at the contact line; with --v-max 0.09 no larger start volume is tried,
    and the run stops (exit 1) naming the inversion instead of accepting the state (the solid's
    own veto rejects the inverted states the homotopy reaches, the scene's guard the rest)."""
    out = tmp_path / "out"
    result = bcfem("run", "blister-soft", "--stiffness-ratio", "2", "--delta-gamma", "0", "--v-max", "0.09",
                   "--size-wetted", "0", "--out", out)
    assert result.returncode == 1, result.stderr[-2000:]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and "inverts" in summary["error"]


@pytest.mark.slow
@pytest.mark.serial
def test_fig_4_8_parameters_start_where_the_branch_exists(tmp_path):
    """Fig. 4.8's parameters (gamma_l = gamma_ls = 0.5, dgamma = 0, ratio 2), adhesive edge, from
    the default --v-start: the start at V/V0 = 0.05 fails, the scene starts from a larger cap and
    traces back until the branch ends (the free membrane compressed everywhere); the run exits
    0, every row has J > 0, and the onset is the one a start at V/V0 = 0.3 finds (one branch)."""
    args = ("blister-soft", "--stiffness-ratio", "2", "--delta-gamma", "0", "--edge", "adhesive", "--v-max", "0.6")
    chosen, out = run(tmp_path, "chosen", *args)
    given, _ = run(tmp_path, "given", *args, "--v-start", "0.3")
    rows = read_csv(out / "branch.csv")
    assert min(row["J_min"] for row in rows) > 0
    start = chosen["branch_start"]
    assert start["v_start"] == 0.05 and rows[0]["V_over_V0"] == pytest.approx(start["V_over_V0"], rel=1e-12)
    assert 0.05 < start["V_over_V0"] < chosen["delamination_onset"]["V_over_V0"]
    assert rows[0]["compressed_fraction"] == pytest.approx(1.0)
    assert given["branch_start"] is None
    for key in ("V_over_V0", "P", "r1_over_R0"):
        assert chosen["delamination_onset"][key] == pytest.approx(given["delamination_onset"][key], rel=1e-6)


@pytest.mark.serial
def test_a_block_too_small_for_the_moving_front_exits_2_before_meshing(tmp_path):
    out = tmp_path / "out"
    line = refused("run", "blister-soft", "--edge", "adhesive", "--size-factor", "2", out=out)
    assert "size-factor" in line and "adhesive" in line
    assert not out.exists()
