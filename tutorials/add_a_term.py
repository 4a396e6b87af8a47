# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Tutorial: add a term to any scene
#
# Every scene's `build(params, comm, *, extra_terms=())` takes energy terms from a research
# script. A term is a frozen dataclass that inherits `bcfem.Term`; its `energy(ctx)` returns
# one scalar UFL form in the reference configuration, and bcfem differentiates the total
# energy for the residual and the tangent. Its numbers reach UFL through
# `ctx.parameters(self)`, so a new value compiles no form.
#
# We put the clamped blister of chapter 3 on a foundation of springs (a Winkler
# foundation of stiffness $k$ per unit area, in units of $\mu_f t_0/R_0^3$):
#
# $$ \Pi = \int t_0 W(I_1)\,dA + \int \tfrac{k}{2} w^2\,dA - \Delta p\,V , $$
#
# and check two limits:
#
# * without springs, small deflections follow the Föppl–Hencky membrane:
#   $w(0)/R_0 = (8P/3)^{1/3} I_1/2$ with $I_1 = \int_0^1 \rho/s\,d\rho = 0.59488$
#   (`bcfem.theory.membrane`);
# * with springs, the membrane's own stiffness is cubic in the deflection and the springs'
#   linear, so as the blister flattens the springs carry the pressure alone: $w(0) = p/k$.
#
# Then we add a term to the crater's load–unload cycle and check an exact equivalence.
#
# Run it as `python tutorials/add_a_term.py` or `mpirun -n 2 python tutorials/add_a_term.py`.

# %%
import math
from dataclasses import dataclass, replace

from mpi4py import MPI

import bcfem
from bcfem.scenes import blister_rigid, crater
from bcfem.theory.membrane import foppl_constants, foppl_deflection

comm = MPI.COMM_WORLD
K = 1.0  # spring stiffness, mu_f t0 / R0^3


def say(text: str) -> None:
    if comm.rank == 0:
        print(text)


# %% [markdown]
# ## The term

# %%
@dataclass(frozen=True)
class SpringFoundation(bcfem.Term):
    r"""A Winkler foundation under a membrane: $\tfrac{k}{2}\int w^2\,dA$ (w = z, the deflection)."""

    k: float  # [mu_f t0 / R0^3]

    def energy(self, ctx):
        k = ctx.parameters(self).k  # this instance's fem.Constant
        return ctx.kin.integral(0.5 * k * ctx.kin.z**2)  # kin.integral applies 2 pi R once


# %% [markdown]
# ## The blister without springs: Föppl–Hencky
# The branch starts at $V/V_0 = 10^{-3}$; its first point is a small deflection.

# %%
params = blister_rigid.Params(material="neo-hookean", v_start=1e-3, v_max=0.02, cells=100)
bare = bcfem.branch_of(blister_rigid.build(params, comm))
first = bare.rows[0]
hencky = foppl_deflection(first["P"])
say(f"I1 = {foppl_constants()[1]:.5f}; at V/V0 = {first['V_over_V0']:.4g}: w(0) = {first['aspect']:.6e}, "
    f"Föppl-Hencky {hencky:.6e}")
assert abs(foppl_constants()[1] - 0.59488) < 5e-6
assert abs(first["aspect"] / hencky - 1) < 1e-4

# %% [markdown]
# ## On springs: $w(0) = p/k$ as the blister flattens

# %%
sprung = bcfem.branch_of(blister_rigid.build(params, comm, extra_terms=[SpringFoundation(K)]))
ratios = [row["aspect"] * K / row["P"] - 1 for row in sprung.rows]
say("w(0) k / p - 1 along the branch: " + ", ".join(f"{r:.2e}" for r in ratios[::max(1, len(ratios) // 4)]))
assert abs(ratios[0]) < 1e-3  # the springs' limit ...
assert abs(ratios[0]) < abs(ratios[-1])  # ... approached as the deflection shrinks

# %% [markdown]
# ## A term in the crater's cycle
# The crater (chapters 7–8) is loaded, sealed and unloaded in stages; an extra term joins
# every stage (a term may name its `stages`). Here the extra term is the specimen's own
# strain energy a second time: a solid twice as stiff, which is the crater at twice
# $\beta = \mu/p_a$ exactly (with no wall surface energy, whose scale is $\mu a$).

# %%
cycle = crater.Params(preload=0.1, surface_energy=0.0, self_contact=0.0, size_crater=0.2, strain_step=0.05)
solid = bcfem.SolidStrain(bcfem.NearlyIncompressibleNeoHookean(mu=cycle.beta, kappa=cycle.kappa_ratio * cycle.beta))
_, doubled = crater.solve(cycle, comm, extra_terms=[solid])
_, stiffer = crater.solve(replace(cycle, beta=2 * cycle.beta), comm)
say(f"F~ with the solid twice {doubled['F_tilde']:.9f}, at 2 beta {stiffer['F_tilde']:.9f}")
assert math.isclose(doubled["F_tilde"], stiffer["F_tilde"], rel_tol=1e-6)
