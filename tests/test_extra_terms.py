"""Every scene takes terms from a research script: ``build(params, comm, *, extra_terms=())``.

For each of the eight scenes:

* a zero term (a constant c = 0 times ∫|u|²; its forms are compiled, their values are zero)
  leaves every row unchanged, bit for bit;
* a second instance of one of the scene's own energy terms changes the result as a closed form
  or an equivalence says: a membrane's strain energy twice is a membrane twice as stiff (the
  pressure of a blister with no surface tension doubles at every volume), a solid's twice is a
  crater at twice β = μ/p_a, a soft substrate's twice is twice its stiffness ratio, and a
  linear substrate twice as stiff (its bulk and its surface tensions) deflects half as far
  under the same loads.
"""

import math
from dataclasses import dataclass, replace

from mpi4py import MPI

import pytest
import ufl

from bcfem import MembraneStrain, NeoHookean, SolidStrain, Term
from bcfem.geometry.substrate import OUTER_TOP, WETTED
from bcfem.physics.composite import Scaled
from bcfem.physics.linear_solid import LinearElasticity, LinearSurfaceTension
from bcfem.physics.materials import NearlyIncompressibleNeoHookean
from bcfem.run.runner import solve_rows
from bcfem.scenes import blister_3d, blister_rigid, blister_soft, crater, crater_cell, crater_double, crater_sector
from bcfem.scenes import droplet_soft as ds

COMM = MPI.COMM_WORLD


@dataclass(frozen=True)
class Nothing(Term):
    """c ∫ |u|² dx with c = 0: a term whose every derivative is zero."""

    c: float = 0.0

    def energy(self, ctx):
        return ctx.parameters(self).c * ufl.inner(ctx.u, ctx.u) * ufl.dx(domain=ctx.mesh)


def same(a, b) -> bool:
    """Equal to the bit (NaN equal to NaN)."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def assert_bitwise(rows, reference):
    assert len(rows) == len(reference)
    for row, ref in zip(rows, reference, strict=True):
        assert row.keys() == ref.keys()
        different = {k: (row[k], ref[k]) for k in row if not same(row[k], ref[k])}
        assert not different, different


def assert_close(rows, reference, keys, rel, scale=None):
    """``rows``' columns ``keys`` equal ``reference``'s (times ``scale[key]``) to ``rel``."""
    assert len(rows) == len(reference)
    for row, ref in zip(rows, reference, strict=True):
        for k in keys:
            want = ref[k] * (scale or {}).get(k, 1.0)
            assert row[k] == pytest.approx(want, rel=rel, abs=rel * 1e-3), (k, row, ref)


def limit_points(scene):
    rows, summary = solve_rows(scene, COMM)
    return rows, [(lp["V_over_V0"], lp["P"]) for lp in summary["limit_points"]]


# -- the membranes: P doubles -----------------------------------------------------------------

def assert_twice_the_pressure(module, params, rel):
    """No term, a zero term, the membrane's strain energy twice: (V, P) of every limit point, P doubled."""
    rows, lps = limit_points(module.build(params, COMM))
    zero, _ = limit_points(module.build(params, COMM, extra_terms=[Nothing()]))
    assert_bitwise(zero, rows)
    _, stiff = limit_points(module.build(params, COMM, extra_terms=[MembraneStrain(NeoHookean())]))
    assert lps and len(stiff) == len(lps)
    for (v, p), (v2, p2) in zip(lps, stiff, strict=True):
        assert v2 == pytest.approx(v, rel=rel) and p2 == pytest.approx(2 * p, rel=rel)


@pytest.mark.mpi
def test_blister_rigid():
    assert_twice_the_pressure(blister_rigid, blister_rigid.Params(material="neo-hookean", alpha=0.0, v_max=1.2,
                                                                  cells=40), 1e-7)


@pytest.mark.slow
def test_blister_3d():
    assert_twice_the_pressure(blister_3d, blister_3d.Params(size=0.25, v_max=1.2), 1e-6)


@pytest.mark.slow
def test_blister_soft():
    """The substrate's energy twice: a substrate of twice the stiffness ratio."""
    params = blister_soft.Params(stiffness_ratio=2.0, v_max=0.6)
    rows, _ = solve_rows(blister_soft.build(params, COMM), COMM)
    zero, _ = solve_rows(blister_soft.build(params, COMM, extra_terms=[Nothing()]), COMM)
    assert_bitwise(zero, rows)
    substrate = Scaled(SolidStrain(NearlyIncompressibleNeoHookean(mu=1.0, kappa=params.kappa_ratio)),
                       "stiffness_ratio", params.stiffness_ratio)
    _, doubled = solve_rows(blister_soft.build(params, COMM, extra_terms=[substrate]), COMM)
    _, stiffer = solve_rows(blister_soft.build(blister_soft.Params(stiffness_ratio=4.0, v_max=0.6), COMM), COMM)
    for a, b in zip(doubled["limit_points"], stiffer["limit_points"], strict=True):
        assert a["P"] == pytest.approx(b["P"], rel=1e-6) and a["V_over_V0"] == pytest.approx(b["V_over_V0"], rel=1e-6)
    assert doubled["steps"] > 0 and doubled["status"] == stiffer["status"] == "ok"


# -- the drop: a linear substrate twice as stiff ----------------------------------------------

@pytest.mark.mpi
def test_droplet_soft():
    params = ds.Params(model="linear", gamma_s=0.3, gamma_l=0.5, gamma_ls=0.6, nu=0.2, size_contact=0.05, width=3)
    _, rows, _ = ds.solve(params, COMM)
    _, zero, _ = ds.solve(params, COMM, extra_terms=[Nothing()])
    assert_bitwise(zero, rows)
    # the substrate's whole stiffness twice: its bulk and its two surface tensions, the loads once
    stiffer = [LinearElasticity(nu=params.nu, pressure_degree=params.degree - 1),
               LinearSurfaceTension(params.gamma_ls, WETTED, "gamma_ls"),
               LinearSurfaceTension(params.gamma_s, OUTER_TOP, "gamma_s")]
    _, stiff, _ = ds.solve(params, COMM, extra_terms=stiffer)
    assert_close(stiff, rows, ["ridge_height", "tip_z"], 1e-9, scale={"ridge_height": 0.5, "tip_z": 0.5})


# -- the craters: the solid twice is twice beta -----------------------------------------------

def assert_twice_beta(module, params, columns):
    """No term, a zero term (bit for bit), and the solid's energy twice, which is the crater at 2 beta."""
    rows, _ = module.solve(params, COMM)
    zero, _ = module.solve(params, COMM, extra_terms=[Nothing()])
    assert_bitwise(zero, rows)
    solid = SolidStrain(NearlyIncompressibleNeoHookean(mu=params.beta, kappa=params.kappa_ratio * params.beta))
    doubled, _ = module.solve(params, COMM, extra_terms=[solid])
    stiffer, _ = module.solve(replace(params, beta=2 * params.beta), COMM)
    assert_close(doubled, stiffer, columns, 1e-6)


@pytest.mark.slow
def test_crater():
    params = crater.Params(preload=0.1, surface_energy=0.0, self_contact=0.0, size_crater=0.12, strain_step=0.05)
    assert_twice_beta(crater, params, ["eps", "V_over_V0", "p_over_pa", "A_over_A0", "F_tilde"])


@pytest.mark.study  # a minute of 3-D cycles; the staged scenes' path is the crater's, checked in CI
def test_crater_cell():
    params = crater_cell.Params(crater_radius=1.0, specimen_height=10.0, filling=0.01, size_wall=0.5, size_far=5.0,
                                preload=0.05, strain_step=0.05)
    assert_twice_beta(crater_cell, params, ["eps", "V_over_V0", "p_over_pa", "F_tilde", "lateral_strain_x"])


@pytest.mark.slow
def test_crater_double():
    params = crater_double.Params(protuberance_radius=0.0, seal="preload", plate="frictionless", size_wall=0.16,
                                  size_contact=0.04, specimen_radius=3.0, specimen_height=3.0, preload=0.05,
                                  strain_step=0.0125, surface_energy=0.0)
    assert_twice_beta(crater_double, params, ["eps", "p_c1_over_pa", "V_c1", "F_tilde"])


@pytest.mark.slow
def test_crater_sector():
    assert_twice_beta(crater_sector, crater_sector.Params(drive="cycle", preload=0.05, steps=2),
                      ["eps", "p_over_pa", "V_over_V0", "F_tilde"])


def test_a_term_may_belong_to_some_stages_only():
    """``stages`` names the stages a term joins (default: every one)."""

    @dataclass(frozen=True)
    class Unloading(Nothing):
        stages = ("unload",)

    assert Nothing().belongs_to("load") and Nothing().belongs_to("unload")
    assert not Unloading().belongs_to("load") and Unloading().belongs_to("unload")
