"""blister-3d --delta-gamma map:FILE: adhesion over the plane from a grid. A uniform map is the
uniform number; maps sampled from the stripes and the radial step give those patterns' onset and
front; a front that leaves the map stops with a message; 2 ranks = serial; bad maps exit 2."""

import json

from mpi4py import MPI

import numpy as np
import pytest

from bcfem.radial_profile import parse as parse_profile
from bcfem.run.runner import solve_rows
from bcfem.run.trace import branch_of
from bcfem.scenes import blister_3d
from bcfem.scenes.blister_3d.pattern import parse
from tests.helpers import bcfem, refused, serial_and_parallel

#: neo-Hookean, alpha = 0.5, gamma_ls - dgamma = 2.5 (blister-rigid --adhesion 2.5)
CASE = {"edge": "adhesive", "alpha": 0.5, "gamma_ls": 3.0}


def write_map(path, xs, ys, dgamma):
    """A map file of dgamma(points) (rows x, y) on the grid xs x ys."""
    X, Y = (c.ravel() for c in np.meshgrid(np.asarray(xs, float), np.asarray(ys, float), indexing="ij"))
    values = np.broadcast_to(dgamma(np.column_stack([X, Y])), X.shape)
    np.savetxt(path, np.column_stack([X, Y, values]), fmt="%.17g", header="x y dgamma")
    return f"map:{path}"


def planar(**params):
    return branch_of(blister_3d.build(blister_3d.Params(**{**CASE, **params}), MPI.COMM_WORLD))


def onset(branch) -> dict:
    return next(e for e in branch.events if e["name"] == "delamination onset")


def test_a_uniform_map_is_the_uniform_adhesion(tmp_path):
    """A map of 0.5 everywhere: the release rate along the circle (which carries the wetting
    term's coordinate derivative) and the pressure are those of --delta-gamma 0.5."""
    grid = np.linspace(-1.5, 1.5, 7)
    text = write_map(tmp_path / "uniform.txt", grid, grid, lambda p: 0.5)
    number, mapped = (planar(delta_gamma=value, size=0.2, v_max=0.6).rows[-1] for value in (0.5, parse(text)))
    for key in ("P", "G_mean", "G_max", "G_min", "energy"):
        assert mapped[key] == pytest.approx(number[key], rel=1e-9, abs=1e-12), key


@pytest.mark.slow
def test_stripes_sampled_on_a_grid_meet_the_stripes(tmp_path):
    """The stripes pattern sampled every 0.0025 R0: the same onset node, the onset's volume
    within 1e-3 at size 0.1 (the two differ by discretisation only: 2.5e-3 at size 0.15,
    3.1e-4 at 0.1, 1.2e-4 at 0.07)."""
    stripes = parse("stripes:0.5:0:1")
    xs = np.linspace(-2, 2, 1601)
    text = write_map(tmp_path / "stripes.txt", xs, [-2.0, 2.0],
                     stripes.at)
    exact, mapped = (onset(planar(delta_gamma=value, size=0.1, v_max=3.5, front_steps=0))
                     for value in (stripes, parse(text)))
    assert (mapped["front_x"], mapped["front_y"]) == pytest.approx((exact["front_x"], exact["front_y"]), abs=1e-9)
    assert mapped["V_over_V0"] == pytest.approx(exact["V_over_V0"], rel=1e-3)


@pytest.mark.slow
def test_a_grid_of_the_radial_step_holds_the_front_as_the_step(tmp_path):
    """The disc of stronger adhesion, step:1.1:0.5:0:0.2, sampled every 0.01 R0: the front grows
    over the map's cells into the step and is held where the radial profile holds it (R_front to
    1e-3; the wetting term's fields follow the moving mesh)."""
    profile = parse_profile("step:1.1:0.5:0:0.2")
    xs = np.linspace(-1.6, 1.6, 321)
    text = write_map(tmp_path / "step.txt", xs, xs, lambda p: np.maximum(profile(np.hypot(p[:, 0], p[:, 1])), 0.0))
    last = {}
    for name, value in (("profile", profile), ("map", parse(text))):
        rows, _ = solve_rows(blister_3d.build(blister_3d.Params(
            **CASE, delta_gamma=value, size=0.1, v_max=6.0, front_steps=3), MPI.COMM_WORLD), MPI.COMM_WORLD)
        last[name] = rows[-1]
    assert last["map"]["R_front"] == pytest.approx(last["profile"]["R_front"], rel=1e-3)
    assert 1.0 < last["map"]["R_front"] < 1.1


def test_a_front_that_leaves_the_map_stops_with_a_message(tmp_path):
    """A map that covers the circle's box only: the growing front leaves it, and the run stops
    (exit 1) saying where, with the converged rows kept."""
    grid = np.linspace(-1.05, 1.05, 3)
    text = write_map(tmp_path / "tight.txt", grid, grid, lambda p: 0.5)
    out = tmp_path / "out"
    done = bcfem("run", "blister-3d", "--edge", "adhesive", "--alpha", "0.5", "--delta-gamma", text, "--size",
                 "0.2", "--v-max", "4", "--front-steps", "2", "--quiet", "--no-plots", "--out", out)
    assert done.returncode == 1
    assert "lies off the map" in done.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["delamination_onset"] is not None


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.serial
def test_two_ranks_equal_serial_on_a_map(tmp_path):
    """Stripes across the circle on a coarse grid, to past the onset with two front moves: 2 ranks
    give the serial onset and front."""
    xs = np.linspace(-2, 2, 81)
    text = write_map(tmp_path / "map.txt", xs, [-2.0, 2.0], lambda p: 0.5 - 0.5 * np.cos(4 * np.pi * p[:, 0]))
    serial, parallel = serial_and_parallel(tmp_path, "run", "blister-3d", "--edge", "adhesive", "--alpha", "0.5",
                                           "--delta-gamma", text, "--size", "0.2", "--v-max", "1.8",
                                           "--front-steps", "2", "--quiet", "--no-plots")
    assert parallel["delamination_onset"]["V_over_V0"] == pytest.approx(
        serial["delamination_onset"]["V_over_V0"], rel=1e-8)
    assert parallel["front"]["R_front"] == pytest.approx(serial["front"]["R_front"], rel=1e-6)


@pytest.mark.parametrize("rows, message", [
    ("0 0 0.5\n1 0 0.5\n0 1 0.5\n1 1 0.5\n", "must cover the outline's bounding box"),
    ("-2 -2 0.5\n2 -2 0.5\n-2 2 0.5\n", "rectangular grid"),  # a node missing
    ("-2 -2 0.5\n2 -2 0.5\n-2 2 0.5\n-2 2 0.5\n", "names a node twice"),
    ("-2 -2 0.5\n2 -2\n-2 2 0.5\n2 2 0.5\n", "a row is 'x y value'"),
    ("-2 -2 0.5\n2 -2 nan\n-2 2 0.5\n2 2 0.5\n", "expected a finite number"),
    ("-2 -2 0.5\n2 -2 4\n-2 2 0.5\n2 2 0.5\n", "debonding must cost energy"),  # 4 > alpha + gamma_ls
])
def test_bad_map_exits_2(tmp_path, rows, message):
    path = tmp_path / "map.txt"
    path.write_text(rows)
    line = refused("run", "blister-3d", "--edge", "adhesive", "--delta-gamma", f"map:{path}", out=tmp_path / "out")
    assert "--delta-gamma" in line or str(path) in line
    assert message in line


def test_a_missing_map_exits_2(tmp_path):
    assert "cannot read the map" in refused("run", "blister-3d", "--edge", "adhesive", "--delta-gamma",
                                            f"map:{tmp_path / 'none.txt'}", out=tmp_path / "out")
