"""blister-3d: the planar-reference membrane against the axisymmetric blister, its mesh
convergence, its outlines' checks, and 2 ranks against serial."""

import json
import math
from pathlib import Path

from mpi4py import MPI

import numpy as np
import pytest

from bcfem.geometry.outline import check_polygon
from bcfem.run.trace import branch_of
from bcfem.scenes import blister_3d
from tests.helpers import bcfem, refused

#: a polygon outline (--mesh mirrored takes a circle, an ellipse or a rectangle only)
HEXAGON = Path(__file__).resolve().parent.parent / "docs" / "figures" / "blister_3d" / "hexagon.txt"

#: blister-rigid's P_max, neo-Hookean, alpha = 0 (the axisymmetric scene at 400 P2 cells)
NEO_HOOKEAN_P_MAX = 1.879173


def limit_points(**params):
    branch = branch_of(blister_3d.build(blister_3d.Params(**params), MPI.COMM_WORLD))
    return {lp.kind: lp.values for lp in branch.limit_points}


def test_circle_reproduces_the_axisymmetric_maximum():
    top = limit_points(size=0.2, v_max=1.0)["max"]
    assert top["P"] == pytest.approx(NEO_HOOKEAN_P_MAX, abs=1e-3)


@pytest.mark.slow
def test_gent_circle_has_both_axisymmetric_extrema():
    """Gent Jm = 100, alpha = 0.5: the N-shaped branch's maximum and minimum, against
    blister-rigid on the same parameters."""
    from bcfem.run.trace import branch_of as trace
    from bcfem.scenes import blister_rigid

    reference = trace(blister_rigid.build(blister_rigid.Params(material="gent", Jm=100, alpha=0.5, v_max=6),
                                          MPI.COMM_WORLD))
    expected = {lp.kind: lp.values["P"] for lp in reference.limit_points}
    found = limit_points(material="gent", Jm=100, alpha=0.5, v_max=6, size=0.2)
    for kind in ("max", "min"):
        assert found[kind]["P"] == pytest.approx(expected[kind], rel=1e-3), kind


@pytest.mark.slow
def test_maximum_converges_at_a_high_rate():
    """P2 on quadratic cells: the error of P_max against the finest of three meshes (a
    Richardson-free check: the finest is itself within 1e-5 of the axisymmetric value)."""
    sizes = (0.4, 0.2, 0.1)
    errors = [abs(limit_points(size=h, v_max=1.0)["max"]["P"] - NEO_HOOKEAN_P_MAX) for h in sizes]
    rates = [math.log(errors[i] / errors[i + 1], 2) for i in range(2)]
    print("P_max errors", errors, "observed rates", rates)
    assert errors[-1] < 1e-4
    assert min(rates) > 2.5


@pytest.mark.slow
def test_ellipse_inflates_to_a_rounder_dome():
    """An ellipse of aspect 2: its apex stays on the centre and its branch has a maximum above
    the circle's (the short axis curves more at the same volume)."""
    top = limit_points(outline="ellipse", aspect=2.0, size=0.2, v_max=1.0)["max"]
    assert top["P"] > NEO_HOOKEAN_P_MAX


def foppl_constant(aspect: float, size: float) -> float:
    """K = P a^4 / h^3 of a rectangle of half-width a at small deflection (h/a < 0.01)."""
    scene = blister_3d.build(blister_3d.Params(outline="rectangle", aspect=aspect, size=size, v_start=5e-4,
                                               v_max=1e-3), MPI.COMM_WORLD)
    row = branch_of(scene).rows[0]
    a = math.sqrt(math.pi / aspect) / 2
    return row["P"] * a**4 / row["aspect"] ** 3


def test_long_rectangle_is_the_plane_strain_bulge():
    """Aspect 8: the plane-strain membrane, p = (4/3) E t h^3 / ((1 - nu^2) a^4) = (16/3) mu t h^3 / a^4
    for an incompressible material (E = 3 mu, nu = 1/2)."""
    assert foppl_constant(8, 0.06) == pytest.approx(16 / 3, rel=1e-3)


@pytest.mark.slow
def test_square_bulge_is_vlassak_and_nix():
    """A square of half-side a: p = (0.8 + 0.062 nu)^-3 E t h^3 / ((1 - nu) a^4) (Vlassak and Nix
    1992, an energy approximation quoted to about 1 %): 10.456 mu t h^3 / a^4 at nu = 1/2."""
    vlassak_nix = (0.8 + 0.062 * 0.5) ** -3 * 3 / (1 - 0.5)
    assert foppl_constant(1, 0.1) == pytest.approx(vlassak_nix, rel=1e-2)


@pytest.mark.slow
def test_relaxed_circle_is_taut():
    """An inflated circle is in tension everywhere: the tension-field relaxation changes nothing."""
    taut = limit_points(size=0.4, v_max=1.0)["max"]
    relaxed = limit_points(size=0.4, v_max=1.0, wrinkles="relaxed")["max"]
    assert relaxed["wrinkled_fraction"] == 0
    assert relaxed["P"] == pytest.approx(taut["P"], rel=1e-12)


@pytest.mark.slow
def test_rectangle_wrinkles_at_its_corners():
    """A clamped rectangle of aspect 4 before its maximum: the taut membrane's minor tension
    is negative only at the corners (sampled on a grid of the quarter), where the relaxed
    membrane wrinkles; the centre is in biaxial tension."""
    from bcfem.mpi import sample

    scene = blister_3d.build(blister_3d.Params(outline="rectangle", aspect=4, size=0.1, v_max=0.35,
                                               wrinkles="relaxed"), MPI.COMM_WORLD)
    end = branch_of(scene).rows[-1]
    assert 0 < end["wrinkled_fraction"] < 0.05
    half_w, half_h = math.sqrt(4 * math.pi) / 2, math.sqrt(math.pi / 4) / 2
    grid = np.array([[fx * half_w, fy * half_h, 0] for fx in np.linspace(0, 0.98, 8)
                     for fy in np.linspace(0, 0.98, 6)])
    minor = sample(scene.fields[1], grid)[:, 2]  # 'measures': lambda_1, lambda_2, N2
    compressed = grid[minor < 0]
    assert len(compressed) > 0 and minor[0] > 0
    assert np.all(compressed[:, 0] > half_w - 2 * half_h) and np.all(compressed[:, 1] > 0.5 * half_h)


def test_a_self_intersecting_polygon_is_refused():
    with pytest.raises(ValueError, match="self-intersecting"):
        check_polygon(np.array([[0, 0], [1, 1], [1, 0], [0, 1]], dtype=float))
    check_polygon(np.array([[0, 0], [2, 0], [2, 1], [0, 1]], dtype=float))


@pytest.mark.parametrize("argv, name", [
    (["--outline", "polygon"], "--vertices"),
    (["--outline", "circle", "--aspect", "2"], "--aspect"),
    (["--aspect", "0"], "--aspect"),
    (["--size", "0.001"], "--size"),
    (["--outline", "polygon", "--vertices", str(HEXAGON), "--mesh", "mirrored"], "--mesh"),
    (["--edge", "adhesive", "--follow", "broken"], "--follow"),
    (["--mesh", "quarter"], "--mesh"),
])
def test_bad_input_exits_2(tmp_path, argv, name):
    assert name in refused("run", "blister-3d", *argv, out=tmp_path / "out")


def test_a_bad_vertex_file_exits_2(tmp_path):
    bowtie = tmp_path / "bowtie.txt"
    bowtie.write_text("0 0\n1 1\n1 0\n0 1\n")
    assert "--vertices" in refused("run", "blister-3d", "--outline", "polygon", "--vertices", bowtie,
                                   out=tmp_path / "out")


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.serial
def test_two_ranks_equal_serial(tmp_path):
    runs = {}
    for ranks in (1, 2):
        out = tmp_path / f"n{ranks}"
        done = bcfem("run", "blister-3d", "--outline", "rectangle", "--aspect", "2", "--size", "0.4",
                     "--v-max", "1", "--quiet", "--no-plots", "--out", out, ranks=ranks)
        assert done.returncode == 0, done.stderr
        runs[ranks] = json.loads((out / "summary.json").read_text())
    (serial,), (parallel,) = runs[1]["limit_points"], runs[2]["limit_points"]
    assert parallel["P"] == pytest.approx(serial["P"], rel=1e-9)
    assert parallel["V_over_V0"] == pytest.approx(serial["V_over_V0"], rel=1e-8)
