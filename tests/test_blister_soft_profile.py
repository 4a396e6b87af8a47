"""``blister-soft --delta-gamma`` as a radial profile dgamma(R) of the substrate's material radius.

* the profiles as read from text: the sharp profile outside the smoothing windows, within the
  named values inside, their area integral; bad texts exit 2 before meshing;
* a uniform profile given as a table is the number (energies, residual, release rate);
* the bonded energy of a homogeneous stretch in closed form, Taylor rates with a step at the
  front (R1 included: the release rate is the energy's R1-derivative with dgamma moving
  through the material radius X(xi; R1)), 2 ranks equal COMM_SELF (marker ``mpi``);
* a step down in dgamma (the debonding cost alpha + gamma_ls - dgamma up) pins the front in
  its window while the pressure grows, and the front leaves it on the uniform-outer branch:
  at R1 = R_s + w/2 the two energies are one, so the states are equal (slow);
* ``mpirun -n 2`` equals serial through the step (slow).
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
from bcfem.radial_profile import RadialProfile, parse
from bcfem.scenes import blister_soft

pytestmark = pytest.mark.mpi

L = 3.0
ADHESIVE = dict(SMALL, edge="adhesive", size_factor=L)  # size_contact 0.05: widths >= 0.1


def model_with(delta_gamma, comm=MPI.COMM_WORLD, radius=1.2, refine=0):
    from bcfem.scenes.blister_soft.model import Model

    model = Model(blister_soft.Params(**dict(ADHESIVE, delta_gamma=delta_gamma, refine=refine)), comm)
    model.ctx.states["debond_radius"].x.array[:] = radius
    return model


@pytest.mark.serial
def test_profiles_read_from_text(tmp_path):
    """Each form is its sharp profile outside the windows |R - rho| < w/2, stays within the
    values it names inside them, and its area integral is the exact one of the smooth profile."""
    table = tmp_path / "dgamma.txt"
    table.write_text("# R dgamma\n1.0 0.5\n1.3, 0.5\n1.5 0.2  # a ramp down\n2.0 0.4\n")
    sharp = {"step:1.2:0.5:0.3": lambda R: np.where(R < 1.2, 0.5, 0.3),
             "step:1.2:0.5:0.3:0.2": lambda R: np.where(R < 1.2, 0.5, 0.3),
             "ramp:1.1:1.4:0.5:0.2": lambda R: np.interp(R, [1.1, 1.4], [0.5, 0.2]),
             f"table:{table}:0.08": lambda R: np.interp(R, [1.0, 1.3, 1.5, 2.0], [0.5, 0.5, 0.2, 0.4])}
    R = np.linspace(0.0, 3.0, 300_001)
    for text, exact in sharp.items():
        profile = parse(text)
        assert isinstance(profile, RadialProfile) and str(profile) == text
        f = profile(R)
        outside = np.all([(R <= a) | (R >= b) for a, b in profile.windows], axis=0)
        assert f[outside] == pytest.approx(exact(R[outside]), abs=1e-14), text
        assert min(profile.values) - 1e-14 <= f.min() and f.max() <= max(profile.values) + 1e-14, text
        inside = (R > 1.0) & (R < 2.5)
        trapezoid = np.trapezoid(f[inside] * 2 * R[inside], R[inside])
        assert profile.area_integral(R[inside][0], R[inside][-1]) == pytest.approx(trapezoid, rel=1e-9), text
    assert parse("0.5") == 0.5 and parse("step:1.2:0.5:0.3").width == 0.05


@pytest.mark.serial
@pytest.mark.parametrize("text, words", [
    ("step:1.2:0.5", "step:R_s:inner:outer"), ("ramp:1.4:1.1:0.5:0.2", "radii must increase"),
    ("step:1.2:0.5:-0.1", "every value of --delta-gamma"), ("wiggle:1:2", "expected a number or a profile"),
    ("table:no-such-file", "cannot read the table"), ("step:1.2:0.5:0.3:0.01", "2 elements at the contact line"),
    ("step:1.2:0.5:0.3:0", "smoothing width"), ("step:inf:0.5:0.3", "finite number")])
def test_bad_profiles_exit_2_before_meshing(tmp_path, text, words):
    line = refused("run", "blister-soft", "--edge", "adhesive", "--delta-gamma", text, out=tmp_path / "out")
    assert words in line and "delta-gamma" in line


def off_equilibrium(model):
    """The front free, a cap of V/V0 = 0.35 on a substrate sheared and lifted towards the
    contact line (zero on the bottom and the far side), a pressure off the equilibrium one."""
    model.front.value = 1.0
    model.cap_guess(0.35)
    depth = lambda x: (x[1] + L) / L  # noqa: E731
    model.u.interpolate(lambda x: np.vstack([0.1 * np.sin(math.pi * x[0] / L) * depth(x),
                                             0.08 * np.exp(-((x[0] - 1) ** 2)) * depth(x) ** 2]))
    model.ctx.states["solid_pressure"].interpolate(lambda x: 0.3 - 0.05 * x[1])
    model.ctx.real_state("pressure").x.array[:] = 1.2
    return model


def release_rate(model):
    R1 = model.ctx.states["debond_radius"]
    one = fem.Function(R1.function_space)
    one.x.array[:] = 1.0
    return global_sum(model.form(ufl.derivative(sum(t.energy(model.ctx) for t in model.terms), R1, one)))


@pytest.mark.serial
def test_a_uniform_table_is_the_number(tmp_path):
    """dgamma = 0.3 as a number and as a table of equal rows: at a debonded, off-equilibrium
    state every term's energy, the residual, the release rate and the reported energy's offset
    are the same to round-off."""
    table = tmp_path / "uniform.txt"
    table.write_text("0.5 0.3\n1.2 0.3\n2.0 0.3\n")
    models = [off_equilibrium(model_with(value, MPI.COMM_SELF, radius=1.15))
              for value in (0.3, parse(f"table:{table}"))]
    energies = [{t.name: global_sum(m.form(t.energy(m.ctx))) for t in m.terms} for m in models]
    assert energies[1] == pytest.approx(energies[0], rel=1e-13, abs=1e-15)
    residuals = []
    for m in models:
        v = ufl.TestFunction(m.u.function_space)
        residuals.append(fem.assemble_vector(m.form(ufl.derivative(sum(t.energy(m.ctx) for t in m.terms), m.u, v)))
                         .array.copy())
    assert residuals[1] == pytest.approx(residuals[0], rel=1e-13, abs=1e-13 * np.abs(residuals[0]).max())
    assert release_rate(models[1]) == pytest.approx(release_rate(models[0]), rel=1e-13)
    assert models[1].energy_offset == pytest.approx(models[0].energy_offset, rel=1e-14)


def test_bonded_energy_of_a_homogeneous_stretch_in_closed_form():
    """Debonded to R1 = 1.2 and stretched about the material points, x = (1+a) X: the bonded
    interface's energy is (1+a)^2 pi int_R1^L dgamma(R) 2R dR, dgamma at the material radius.
    The graded mesh's quadrature of the ramp's C3 corners (w = 0.3) converges: halving every
    element divides its error by more than 8, to below 1e-7."""
    R1, a = 1.2, 0.07
    profile = parse("ramp:1.4:2.2:0.5:0.1:0.3")
    errors = []
    for refine in (0, 1):
        model = model_with(profile, radius=R1, refine=refine)
        solid = model.ctx.kin
        V = model.u.function_space
        model.u.interpolate(fem.Expression((1 + a) * solid.X - solid.x, V.element.interpolation_points))
        term = next(t for t in model.terms if t.name == "delta_gamma@delta_gamma")
        got = global_sum(model.form(term.energy(model.ctx)))
        errors.append(abs(got / ((1 + a) ** 2 * math.pi * profile.area_integral(R1, L)) - 1))
    assert errors[1] < errors[0] / 8 and errors[1] < 1e-7, errors
    # the free membrane's strain energy is still that of the material disc R < R1
    free = next(t for t in model.terms if t.name == "membrane_strain@free")
    assert global_sum(model.form(free.energy(model.ctx))) == pytest.approx(math.pi * R1**2 * W(1 + a), rel=1e-11)


def taylor_with_a_step_at_the_front(comm):
    """A step of width 0.2 across the front R1 = 1.15, along a direction that moves the front."""
    model = off_equilibrium(model_with(parse("step:1.17:0.6:0.1:0.2"), comm, radius=1.15))
    return taylor_of(model, f"bcfem_test_profile_{comm.size}_", extra={"debond_radius": 0.5})


def test_taylor_rates_and_ranks_with_a_step_at_the_front():
    assert_battery(taylor_with_a_step_at_the_front)


#: the pinning case: Fig. 4.5's tensions at stiffness ratio 2; dgamma falls from 0.5 to 0.1 at
#: R_s = 1.1 (the debonding cost alpha + gamma_ls - dgamma rises from 0.5 to 0.9), window w = 0.1
STEP = dict(edge="adhesive", stiffness_ratio=2.0, growth=1.5, size_contact=0.02, v_max=0.8)
R_S, WIDTH = 1.1, 0.1


def trace_to_front(delta_gamma, radius, **changes):
    from bcfem.run.trace import branch_of
    from bcfem.scenes.blister_soft.model import build

    scene = build(blister_soft.Params(**{**STEP, **changes}, delta_gamma=delta_gamma), MPI.COMM_SELF)
    scene.end = lambda values: values["R1_over_R0"] - radius
    return branch_of(scene).rows


@pytest.mark.slow
@pytest.mark.serial
def test_a_step_in_dgamma_pins_the_front_until_the_outer_threshold():
    """Beyond R1 = R_s + w/2 the step's dgamma is the outer value on the whole bonded top, so
    the two energies are equal for every state: the step run leaves its window on the uniform
    dgamma = 0.1 branch, at its V/V0 (the sharp step's limit: the outer run's state at R1 = R_s).
    Before, the front waits in the window: its pressure rises there (a blister held at R_s),
    where the propagating outer branch's falls, and it crosses the window over a larger volume."""
    step = trace_to_front(parse(f"step:{R_S}:0.5:0.1:{WIDTH}"), R_S + WIDTH / 2)
    outer = trace_to_front(0.1, R_S + WIDTH / 2)
    for key in ("V_over_V0", "P", "r1_over_R0", "indentation", "z_apex"):
        assert step[-1][key] == pytest.approx(outer[-1][key], rel=1e-6), key

    def window(rows):
        first = next(r for r in rows if r["R1_over_R0"] >= R_S - WIDTH / 2)
        return first, rows[-1]

    (arrive, leave), (outer_in, outer_out) = window(step), window(outer)
    print(f"step: window entered at V/V0 {arrive['V_over_V0']:.5f} (P {arrive['P']:.5f}), left at "
          f"{leave['V_over_V0']:.5f} (P {leave['P']:.5f}); outer branch crosses it from V/V0 "
          f"{outer_in['V_over_V0']:.5f} (P {outer_in['P']:.5f})")
    front = [r["R1_over_R0"] for r in step]
    assert all(b >= a - 1e-9 for a, b in zip(front, front[1:]))  # no healing, no jump back
    assert leave["P"] - arrive["P"] > 0.2 and outer_out["P"] < outer_in["P"]
    assert leave["V_over_V0"] - arrive["V_over_V0"] > 1.5 * (outer_out["V_over_V0"] - outer_in["V_over_V0"])
    # the front arrived at the step before the outer branch reached it: the inner side is cheaper
    assert arrive["V_over_V0"] < outer_in["V_over_V0"]


@pytest.mark.slow
@pytest.mark.serial
def test_two_ranks_equal_serial_through_a_step(tmp_path):
    args = ("blister-soft", *(f"--{k.replace('_', '-')}={v}" for k, v in STEP.items() if k != "v_max"),
            "--v-max", "0.55", "--delta-gamma", f"step:{R_S}:0.5:0.1:{WIDTH}", "--no-plots")
    runs = []
    for ranks in (1, 2):
        out = tmp_path / f"ranks{ranks}"
        result = bcfem("run", *args, "--out", out, ranks=ranks)
        assert result.returncode == 0, result.stderr[-3000:]
        runs.append((json.loads((out / "summary.json").read_text()), read_csv(out / "branch.csv")))
    (serial, rows1), (parallel, rows2) = runs
    assert parallel["ranks"] == 2 and rows1[-1]["R1_over_R0"] > R_S + WIDTH / 2
    assert parallel["parameters"]["delta_gamma"]["text"] == f"step:{R_S}:0.5:0.1:{WIDTH}"
    pairs = same_loads(rows2, rows1, "s") + [(rows2[-1], rows1[-1])]
    assert pairs[0][0] is rows2[0]
    for mine, theirs in pairs:
        assert mine == pytest.approx(theirs, rel=1e-7, abs=1e-9)


def rigid_rows(adhesion, stop_radius):
    from bcfem.run.trace import branch_of
    from bcfem.scenes import blister_rigid

    params = blister_rigid.Params(material="neo-hookean", alpha=0.5, edge="adhesive", adhesion=adhesion, v_max=1.0,
                                  stop_radius=stop_radius)
    return branch_of(blister_rigid.build(params, MPI.COMM_SELF)).rows


@pytest.mark.serial
def test_a_step_in_the_rigid_adhesion_pins_the_front():
    """blister-rigid --edge adhesive --adhesion step:1.1:0:0.4:0.1 (gamma_ls - dgamma of the
    substrate's radius; the front sees its value at r1 = R1): the front waits in the window,
    its pressure rising, and leaves it on the uniform adhesion-0.4 branch, equal at R1 = 1.15."""
    step = rigid_rows(parse(f"step:{R_S}:0:0.4:{WIDTH}"), R_S + WIDTH / 2)
    outer = rigid_rows(0.4, R_S + WIDTH / 2)
    for key in ("V_over_V0", "P", "aspect", "r1_over_R0"):
        assert step[-1][key] == pytest.approx(outer[-1][key], rel=1e-7), key
    arrive = next(r for r in step if r["R1_over_R0"] >= R_S - WIDTH / 2)
    assert max(r["P"] for r in step) - arrive["P"] > 0.2
    assert arrive["V_over_V0"] < 0.6 * step[-1]["V_over_V0"]


@pytest.mark.serial
def test_a_rigid_adhesion_profile_needs_the_adhesive_edge(tmp_path):
    line = refused("run", "blister-rigid", "--edge", "sliding", "--adhesion", "step:1.1:0:0.4", out=tmp_path / "out")
    assert "--adhesion takes a profile with --edge adhesive only" in line


@pytest.mark.slow
@pytest.mark.serial
def test_the_step_pinned_front_tends_to_the_rigid_one():
    """The soft blister with dgamma = step:1.1:0.5:0.1 (gamma_ls = 0.5) and the rigid one with
    adhesion gamma_ls - dgamma = step:1.1:0:0.4 leave the window at R1 = 1.15 in the same state
    as the substrate stiffens: the error of P there falls about tenfold per decade of the
    stiffness ratio (O(1/ratio)), to 1e-4 at 1e4 (1e3: 7.9e-4, 1e4: 7.8e-5; V/V0 5e-5, 1e-5)."""
    rigid = rigid_rows(parse(f"step:{R_S}:0:0.4:{WIDTH}"), R_S + WIDTH / 2)[-1]
    errors = []
    for ratio in (1e3, 1e4):
        soft = trace_to_front(parse(f"step:{R_S}:0.5:0.1:{WIDTH}"), R_S + WIDTH / 2, stiffness_ratio=ratio,
                              alpha=0.5, gamma_ls=0.5, growth=1.25, size_contact=0.01)[-1]
        errors.append((abs(soft["P"] / rigid["P"] - 1), abs(soft["V_over_V0"] - rigid["V_over_V0"])))
    print("leaving the step, errors (P rel, V/V0) at ratios 1e3, 1e4:", errors)
    assert errors[1][0] < 1e-4 and errors[1][1] < 2e-5, errors
    assert errors[1][0] < errors[0][0] / 5 and errors[1][1] < errors[0][1] / 3, errors
