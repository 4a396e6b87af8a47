"""blister-3d --edge adhesive: the release rate along the outline against the axisymmetric
configurational force, the onset and the moving front against blister-rigid's adhesive edge,
an ellipse's front, 2 ranks against serial, and bad input."""

import math

from mpi4py import MPI

import numpy as np
import pytest

from bcfem.run.runner import solve_rows
from bcfem.run.trace import branch_of
from bcfem.scenes import blister_3d, blister_rigid
from tests.helpers import refused, serial_and_parallel

#: neo-Hookean, alpha = 0.5, gamma_ls - dgamma = 2.5: blister-rigid --adhesion 2.5
CASE = {"edge": "adhesive", "alpha": 0.5, "gamma_ls": 3.0, "delta_gamma": 0.5}
COST = 3.0  # alpha + gamma_ls - dgamma


def rigid(**params):
    """blister-rigid's adhesive edge on the same case: its branch."""
    return branch_of(blister_rigid.build(blister_rigid.Params(
        **{"material": "neo-hookean", "alpha": 0.5, "edge": "adhesive", "adhesion": 2.5, **params}), MPI.COMM_WORLD))


def planar(**params):
    """The arc-length branch of blister-3d on the case (to v-max or the onset)."""
    return branch_of(blister_3d.build(blister_3d.Params(**{**CASE, **params}), MPI.COMM_WORLD))


def grown(**params):
    """(rows, summary) of the whole solve: the branch to the onset, then the front's growth."""
    return solve_rows(blister_3d.build(blister_3d.Params(**{**CASE, **params}), MPI.COMM_WORLD), MPI.COMM_WORLD)


def test_circle_release_rate_is_the_axisymmetric_configurational_force():
    """At V/V0 = 0.6, before the onset: the release rate is uniform along the circle and equals
    blister-rigid's cost - dPi/dR1 / (2 pi) (the derivative of its free energy in the debond radius)."""
    reference = rigid(v_max=0.6).rows[-1]
    expected = COST - reference["dPi_dR1"] / 2  # dPi_dR1 is dPi/dR1 / pi
    branch = planar(size=0.2, v_max=0.6)
    row = branch.rows[-1]
    assert row["V_over_V0"] == pytest.approx(0.6, rel=1e-9)
    assert row["G_mean"] == pytest.approx(expected, abs=1e-3 * COST)
    assert row["G_max"] - row["G_min"] < 1e-3 * COST


@pytest.mark.slow
def test_circle_onset_is_the_axisymmetric_onset():
    """Size 0.1: the onset (the release rate reaches the cost somewhere on the circle) within 2 %
    of blister-rigid's, which its 200 cells give to 1e-6."""
    expected = next(e for e in rigid(v_max=3.5).events if e["name"] == "delamination onset")["V_over_V0"]
    branch = planar(size=0.1, v_max=3.5, front_steps=0)
    found = next(e for e in branch.events if e["name"] == "delamination onset")["V_over_V0"]
    assert found == pytest.approx(expected, rel=2e-2)


@pytest.mark.study
def test_circle_onset_converges():
    """A study (about a minute): the onset's error against blister-rigid over sizes 0.2, 0.1,
    0.05 falls at an observed rate above 2.5 (P2), to below 1e-3 at 0.05."""
    expected = next(e for e in rigid(v_max=3.5).events if e["name"] == "delamination onset")["V_over_V0"]
    errors = []
    for size in (0.2, 0.1, 0.05):
        branch = planar(size=size, v_max=3.5, front_steps=0)
        found = next(e for e in branch.events if e["name"] == "uniform onset")["V_over_V0"]
        errors.append(abs(found / expected - 1))
    rates = [math.log2(errors[i] / errors[i + 1]) for i in range(2)]
    print("onset errors", errors, "rates", rates)
    assert errors[-1] < 1e-3 and min(rates) > 2.5


@pytest.mark.slow
def test_circle_front_grows_as_the_axisymmetric_front():
    """After the onset, at V/V0 = 5.2: the debonded region's equivalent radius within 1 % of
    blister-rigid's debond radius, the pressure within 1e-3, and the front a circle to within one
    element (size 0.1)."""
    volume = 5.2
    reference = rigid(v_max=volume).rows[-1]
    rows, summary = grown(size=0.1, v_max=volume, front_steps=4)
    row = rows[-1]
    assert row["V_over_V0"] == pytest.approx(volume, rel=1e-6)
    assert row["R_front"] == pytest.approx(reference["R1_over_R0"], rel=1e-2)
    assert row["P"] == pytest.approx(reference["P"], rel=1e-3)
    assert row["front_R_max"] - row["front_R_min"] < 0.1


@pytest.mark.slow
def test_ellipse_debonds_along_its_minor_axis():
    """An ellipse of aspect 2: its membrane is steepest across the minor axis, so the onset is at
    an end of the minor axis, far earlier than the circle's; the front then grows across, its
    major axis's ends held (the front rounds off)."""
    rows, summary = grown(outline="ellipse", aspect=2.0, size=0.15, v_max=1.5, front_steps=3)
    onset = summary["delamination_onset"]
    b = 1 / math.sqrt(2)
    assert abs(onset["front_y"]) == pytest.approx(b, rel=2e-2) and abs(onset["front_x"]) < 0.15
    assert onset["V_over_V0"] < 1.0
    last = rows[-1]
    assert last["front_R_max"] == pytest.approx(math.sqrt(2), rel=1e-9)  # the major axis's ends stay
    assert last["front_R_min"] > 1.05 * b


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.serial
def test_two_ranks_equal_serial(tmp_path):
    """A coarse circle to past its onset, the front moved twice: 2 ranks give the serial onset
    and front."""
    serial, parallel = serial_and_parallel(tmp_path, "run", "blister-3d", "--edge", "adhesive", "--alpha", "0.5",
                                           "--size", "0.2", "--v-max", "4", "--front-steps", "2", "--quiet",
                                           "--no-plots")
    assert parallel["delamination_onset"]["V_over_V0"] == pytest.approx(
        serial["delamination_onset"]["V_over_V0"], rel=1e-8)
    assert parallel["front"]["R_front"] == pytest.approx(serial["front"]["R_front"], rel=1e-6)


@pytest.mark.parametrize("argv, name", [
    (["--delta-gamma", "4"], "--delta-gamma"),  # alpha + gamma_ls - dgamma <= 0: no cost to debond
    (["--delta-gamma", "-1"], "--delta-gamma"),
    (["--front-steps", "2.5"], "--front-steps"),
])
def test_bad_adhesion_exits_2(tmp_path, argv, name):
    assert name in refused("run", "blister-3d", "--edge", "adhesive", *argv, out=tmp_path / "out")



@pytest.mark.slow
def test_circle_front_is_held_by_a_disc_of_stronger_adhesion_as_axisymmetric():
    """Δγ a step in the radius (0.5 within 1.1, 0 beyond, width 0.2): the front grows into the
    step and is held there; at V/V0 = 6 its radius is blister-rigid's with the same profile of
    its --adhesion (gamma_ls - dgamma: 2.5 within, 3 beyond) to 0.5 %."""
    from bcfem.radial_profile import parse

    reference = rigid(v_max=6.0, adhesion=parse("step:1.1:2.5:3:0.2")).rows[-1]
    rows, _ = grown(delta_gamma=parse("step:1.1:0.5:0:0.2"), size=0.1, v_max=6.0, front_steps=4)
    assert rows[-1]["R_front"] == pytest.approx(reference["R1_over_R0"], rel=5e-3)
    assert 1.0 < rows[-1]["R_front"] < 1.1


@pytest.mark.slow
def test_stripes_debond_first_where_the_adhesion_is_weakest():
    """Stripes of period 0.5 (dgamma from 0 to 1 in x): the onset is where debonding costs
    least (dgamma near its top, 1), far earlier than the uniform circle's."""
    from bcfem.scenes.blister_3d.pattern import parse

    stripes = parse("stripes:0.5:0:1")
    branch = planar(delta_gamma=stripes, size=0.15, v_max=3.5, front_steps=0)
    onset = next(e for e in branch.events if e["name"] == "delamination onset")
    where = np.array([[onset["front_x"], onset["front_y"]]])
    assert stripes.at(where)[0] > 0.9
    assert onset["V_over_V0"] < 2.0


@pytest.mark.parametrize("argv, name", [
    (["--delta-gamma", "stripes:0:0:1"], "--delta-gamma"),
    (["--delta-gamma", "step:1.1:0.5:0", "--size", "0.1"], "--delta-gamma"),  # width 0.05 < 2 elements
    (["--delta-gamma", "stripes:0.5:0:4"], "--delta-gamma"),  # debonding the stripes costs nothing
])
def test_bad_pattern_exits_2(tmp_path, argv, name):
    assert name in refused("run", "blister-3d", "--edge", "adhesive", *argv, out=tmp_path / "out")
