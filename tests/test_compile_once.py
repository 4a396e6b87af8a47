"""Compile once: a form depends on its structure (terms, elements, kinematics), never on a
parameter's value, and a term owns its constants.

* two instances of one term with different values are two values: the energy is their sum,
  serially and on 2 ranks (marker ``mpi``), and their forms have one signature;
* a material's moduli, a wetting energy, a ratio: new values give forms of the same signature
  (what FFCx's cache is keyed by), so nothing is compiled again;
* from an empty form cache, a CLI run with a new value of a parameter compiles no form, and a
  sweep of three values compiles the forms of its first point only (counted by :mod:`bcfem.jit`).
"""

import json
import math
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from mpi4py import MPI

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh

from bcfem import AxisymmetricMembrane, Context, Gent, MembraneStrain, NeoHookean, SurfaceTension, Term, global_sum
from bcfem.physics.energies import WettedSubstrate

BCFEM = [sys.executable, "-m", "bcfem"]


@dataclass(frozen=True)
class Spring(Term):
    r"""A foundation of springs, :math:`\tfrac{k}{2}\int |u|^2\,dx`, as a research script writes it."""

    k: float  # [N/m^3]
    name = "spring"
    multipliers = ()

    def energy(self, ctx):
        k = ctx.parameters(self).k
        return 0.5 * k * ufl.inner(ctx.u, ctx.u) * ufl.dx(domain=ctx.mesh)


def square_ctx(comm=MPI.COMM_WORLD) -> Context:
    """u = (x, 0) on the unit square: (1/2)∫|u|² = 1/6."""
    msh = mesh.create_unit_square(comm, 6, 6)
    u = fem.Function(fem.functionspace(msh, ("Lagrange", 1, (2,))))
    u.interpolate(lambda x: np.vstack([x[0], 0 * x[0]]))
    return Context(u)


def membrane_ctx(comm=MPI.COMM_WORLD) -> Context:
    """A stretched flat membrane on R in [0, 1]: r = 1.2 R, so the current area is 1.44 π."""
    msh = mesh.create_interval(comm, 8, [0.0, 1.0])
    u = fem.Function(fem.functionspace(msh, ("Lagrange", 2, (2,))))
    u.interpolate(lambda x: np.vstack([0.2 * x[0], 0 * x[0]]))
    return Context(u, AxisymmetricMembrane(u, quadrature_degree=6))


@pytest.mark.mpi
def test_two_instances_of_one_term_are_two_values():
    ctx = square_ctx()
    soft, stiff = Spring(1.0), Spring(5.0)
    assert global_sum(fem.form(soft.energy(ctx))) == pytest.approx(1 / 6, rel=1e-12)
    assert global_sum(fem.form(stiff.energy(ctx))) == pytest.approx(5 / 6, rel=1e-12)
    assert global_sum(fem.form(soft.energy(ctx) + stiff.energy(ctx))) == pytest.approx(1.0, rel=1e-12)
    # one structure, one signature: the second value compiles nothing
    assert soft.energy(ctx).signature() == stiff.energy(ctx).signature()
    # a term's constants are its own, and the same on every request
    assert ctx.parameter(soft, "k") is not ctx.parameter(stiff, "k")
    assert ctx.parameter(soft, "k") is ctx.parameters(soft).k


@pytest.mark.mpi
def test_library_terms_of_one_name_keep_their_values_and_are_set_together():
    ctx = membrane_ctx()
    wet, wetter = SurfaceTension(0.5), SurfaceTension(0.3)  # one default name, "gamma_l"
    area = 1.44 * math.pi
    energy = fem.form(wet.energy(ctx) + wetter.energy(ctx))
    assert global_sum(energy) == pytest.approx(0.8 * area, rel=1e-12)
    ctx.set("gamma_l", 2.0)  # a ramp of every gamma_l
    assert global_sum(energy) == pytest.approx(4.0 * area, rel=1e-12)
    assert ctx.value("gamma_l") == 2.0
    with pytest.raises(ValueError, match="ctx.set"):
        ctx.constant("gamma_l")  # a term's parameter is no model control
    with pytest.raises(KeyError, match="no run-time constant"):
        ctx.set("gamma_x", 1.0)


def test_a_new_value_gives_a_form_of_the_same_signature():
    ctx = membrane_ctx(MPI.COMM_SELF)

    def signature(*terms):
        return sum(t.energy(ctx) for t in terms).signature()

    assert signature(MembraneStrain(Gent(Jm=100.0))) == signature(MembraneStrain(Gent(mu=2.0, Jm=50.0)))
    assert signature(MembraneStrain(NeoHookean(), thickness=1.0)) == signature(MembraneStrain(NeoHookean(3.0), 0.5))
    assert signature(WettedSubstrate(-1.0)) == signature(WettedSubstrate(2.5))
    # structure: Gent's Jm = inf is neo-Hookean, another form
    assert signature(MembraneStrain(Gent(Jm=math.inf))) == signature(MembraneStrain(NeoHookean()))
    assert signature(MembraneStrain(Gent(Jm=math.inf))) != signature(MembraneStrain(Gent(Jm=100.0)))


def _in_empty_cache(tmp_path: Path) -> dict:
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "cache"))
    env.pop("PETSC_OPTIONS", None)
    return env


def _run(args, env, out: Path) -> dict:
    subprocess.run([*BCFEM, *args, "--out", str(out), "--quiet", "--no-plots"], env=env, check=True,
                   capture_output=True, timeout=600)
    return json.loads((out / "summary.json").read_text())


@pytest.mark.serial
def test_a_new_material_value_compiles_no_form(tmp_path):
    env = _in_empty_cache(tmp_path)
    base = ["run", "blister-rigid", "--material", "gent", "--v-max", "1.5", "--cells", "40"]
    first = _run([*base, "--Jm", "100", "--alpha", "0.5"], env, tmp_path / "a")
    second = _run([*base, "--Jm", "50", "--alpha", "0.7"], env, tmp_path / "b")
    assert first["jit"]["compiled"] > 0
    assert second["jit"]["compiled"] == 0
    assert second["jit"]["loaded"] == first["jit"]["compiled"] + first["jit"]["loaded"]
    assert second["time_split_s"]["jit"] <= second["wall_time_s"]


@pytest.mark.serial
def test_a_sweep_compiles_the_forms_of_one_point(tmp_path):
    env = _in_empty_cache(tmp_path)
    out = tmp_path / "sweep"
    subprocess.run([*BCFEM, "sweep", "blister-rigid", "--material", "gent", "--v-max", "1.5", "--cells", "40",
                    "--grid", "Jm=40,60,80", "--out", str(out), "--quiet"],
                   env=env, check=True, capture_output=True, timeout=600)
    points = [json.loads(p.read_text()) for p in sorted((out / "points").glob("*.json"))]
    compiled = sorted(p["forms_compiled"] for p in points)
    assert len(points) == 3 and all(p["status"] == "ok" for p in points)
    assert compiled[0] == compiled[1] == 0 < compiled[2]


#: scene, the flags of both runs, the first run's values, the second's (a new value of each)
NEW_VALUES = {
    "crater": (["--preload", "0.1"], ["--beta", "0.5"], ["--beta", "0.61"]),
    "blister-soft": ([], ["--stiffness-ratio", "2"], ["--stiffness-ratio", "3"]),
    "crater-cell": (["--preload", "0.05", "--size-wall", "0.3", "--size-rim", "0.1", "--size-far", "0.8"],
                    ["--beta", "0.5"], ["--beta", "0.61"]),
    "droplet-soft": (["--model", "neo-hookean"], ["--gamma-l", "0.15", "--kappa", "1000"],
                     ["--gamma-l", "0.18", "--kappa", "2000", "--gamma-s", "0.15"]),
    "blister-3d": (["--material", "gent", "--size", "0.2", "--v-max", "1"], ["--Jm", "100", "--alpha", "0.5"],
                   ["--Jm", "50", "--alpha", "0.6"]),
    "crater-sector": ([], ["--beta", "0.5"], ["--beta", "0.6"]),
}


@pytest.mark.slow
@pytest.mark.serial
@pytest.mark.parametrize("scene", [pytest.param(s, marks=pytest.mark.study) if s == "crater-cell" else s
                                   for s in sorted(NEW_VALUES)])
def test_a_new_value_of_a_scene_compiles_no_form(scene, tmp_path):
    """The issue's check: from an empty cache, a run, then one with new values compiles nothing."""
    env = _in_empty_cache(tmp_path)
    flags, first, second = NEW_VALUES[scene]
    cold = _run(["run", scene, *flags, *first], env, tmp_path / "a")
    new = _run(["run", scene, *flags, *second], env, tmp_path / "b")
    assert cold["jit"]["compiled"] > 0 and cold["status"] == new["status"] == "ok"
    assert new["jit"]["compiled"] == 0, f"{scene}: a new value compiled {new['jit']['compiled']} forms"
