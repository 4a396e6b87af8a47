# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Tutorial: a scene from nothing — the thin spherical balloon
#
# A scene is a mesh and its kinematics, a list of energy terms, the boundary conditions and a
# load path. Here we build one that bcfem does not ship: a thin incompressible spherical
# balloon of radius $R$ and thickness $t$, inflated by a pressure $p$ through its limit
# points. The library's terms do the physics: `MembraneStrain` (with a neo-Hookean and a
# Mooney–Rivlin material) and `PressureVolume` (the pressure a global unknown, the volume's
# multiplier); all we write is the kinematics of a membrane on a sphere.
#
# Uniform inflation by $\lambda$ has $I_1 = 2\lambda^2 + \lambda^{-4}$,
# $I_2 = \lambda^4 + 2\lambda^{-2}$, and with $W = C_1(I_1 - 3) + C_2(I_2 - 3)$
#
# $$ \frac{pR}{t} = 4\left(\frac{1}{\lambda} - \frac{1}{\lambda^7}\right)(C_1 + C_2\lambda^2), $$
#
# whose maximum (neo-Hookean: at $\lambda = 7^{1/6}$) and, for $C_2/C_1$ large enough,
# minimum the arc-length continuation must find.
#
# Run it as `python tutorials/scene_from_nothing.py` or under `mpirun -n 2`.

# %%
import math

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem, mesh
from scipy.optimize import brentq

import bcfem
from bcfem.physics.bcs import component

comm = MPI.COMM_WORLD
CELLS, DEGREE = 24, 2
LAM_MAX = 3.6  # the branch ends at this stretch


def say(text: str) -> None:
    if comm.rank == 0:
        print(text)


def pressure(lam, C1, C2):
    """p R / t of the uniformly inflated balloon."""
    return 4 * (1 / lam - 1 / lam**7) * (C1 + C2 * lam**2)


# %% [markdown]
# ## The kinematics: a membrane on a sphere
# The reference meridian is the polar angle $\phi \in [0, \pi/2]$ of the upper half (the
# equator is a mirror plane, which also removes the rigid vertical translation). A material
# point moves to radius $\rho = R + u_0$ and polar angle $\psi = \phi + u_1$, so uniform
# inflation ($u_0$ constant, $u_1 = 0$) is exact in the finite-element space. With
# $dA = 2\pi R^2\sin\phi\,d\phi$: $\lambda_s = \sqrt{\rho'^2 + \rho^2\psi'^2}/R$,
# $\lambda_\theta = \rho\sin\psi/(R\sin\phi)$, and the enclosed volume
# $V = \int_0^{\pi/2} \tfrac{2\pi}{3}\rho^3\sin\psi\,\psi'\,d\phi$. The class offers what the
# two terms read: `I1`, `I2`, `integral`, `mean`, `volume_density`, `reference_area`.

# %%
class SphericalMembrane:
    """An incompressible membrane on the upper half of a sphere of radius ``radius``."""

    def __init__(self, u, radius: float, quadrature_degree: int):
        phi = ufl.SpatialCoordinate(u.function_space.mesh)[0]
        rho, psi = radius + u[0], phi + u[1]
        self.R, self.phi = radius, phi
        self.lam_r = ufl.sqrt(rho.dx(0) ** 2 + (rho * psi.dx(0)) ** 2) / radius
        self.lam_theta = rho * ufl.sin(psi) / (radius * ufl.sin(phi))
        self.I1 = self.lam_r**2 + self.lam_theta**2 + 1 / (self.lam_r * self.lam_theta) ** 2
        self.I2 = (self.lam_r * self.lam_theta) ** 2 + 1 / self.lam_r**2 + 1 / self.lam_theta**2
        self.reference_area = 2 * math.pi * radius**2
        # the volume per reference area: (2 pi / 3) rho^3 sin(psi) psi' / (2 pi R^2 sin(phi))
        self.volume_density = rho**3 * ufl.sin(psi) * psi.dx(0) / (3 * radius**2 * ufl.sin(phi))
        self._dx = ufl.Measure("dx", metadata={"quadrature_degree": quadrature_degree})

    def integral(self, density, region=None):
        return density * 2 * ufl.pi * self.R**2 * ufl.sin(self.phi) * self._dx

    def mean(self, density):
        return self.integral(density / self.reference_area)


# %% [markdown]
# ## The scene
# `BranchScene` traces it by arc-length with the pressure as the load: it needs a start
# (a guess at a small inflation, and its pressure), the observables, and where to end.

# %%
def balloon(material, lam_max: float = LAM_MAX) -> bcfem.BranchScene:
    msh = mesh.create_interval(comm, CELLS, [0.0, math.pi / 2])
    V = fem.functionspace(msh, ("Lagrange", DEGREE, (2,)))
    u = fem.Function(V, name="displacement")
    ctx = bcfem.Context(u, SphericalMembrane(u, 1.0, 2 * DEGREE + 6))
    terms = [bcfem.MembraneStrain(material), bcfem.PressureVolume()]
    poles = mesh.locate_entities_boundary(msh, 0, lambda x: np.isclose(x[0], 0) | np.isclose(x[0], math.pi / 2))
    bcs = [component(V, 1, poles)]  # psi = phi at the pole and on the equator
    V0 = 2 * math.pi / 3
    # the row of each accepted point: the shared observables, and the stretch they give
    observed = [bcfem.cavity_volume(ctx.kin.integral(ctx.kin.volume_density), V0),
                bcfem.RealState(bcfem.Column("P", "mu t / R", "pressure p R / (mu t)"), ctx.real_state("pressure"))]

    def start(fraction: float = 1.0) -> float:
        lam = 1 + 0.02 * fraction
        u.interpolate(lambda x: np.vstack([(lam - 1) + 0 * x[0], 0 * x[0]]))
        return pressure(lam, material.C1, material.C2)

    def observe() -> dict:
        values = bcfem.row(observed)
        return {**values, "lam": values["V_over_V0"] ** (1 / 3)}

    return bcfem.BranchScene(name="balloon", ctx=ctx, terms=terms, bcs=bcs, load="pressure", start=start,
                             observe=observe, end=bcfem.Reaches("lam", lam_max), progress_keys=("lam", "P"))


# %% [markdown]
# ## Neo-Hookean ($C_2 = 0$) and Mooney–Rivlin ($C_2/C_1 = 1/9$), both of shear modulus $\mu = 2(C_1 + C_2) = 1$
# The closed form's extrema come from $dP/d\lambda = 0$; the located limit points must
# meet them (and every point of the branch the curve). The Mooney–Rivlin balloon's curve is
# N-shaped: a maximum, then a minimum past which the I2 term stiffens it again.

# %%
for C1, C2 in ((0.5, 0.0), (0.45, 0.05)):
    branch = bcfem.branch_of(balloon(bcfem.MooneyRivlin(C1, C2)))
    worst = max(abs(row["P"] / pressure(row["lam"], C1, C2) - 1) for row in branch.rows)
    grid = np.linspace(1.01, LAM_MAX, 4000)
    slope = np.gradient(pressure(grid, C1, C2), grid)
    exact = [brentq(lambda lam: (pressure(lam * (1 + 1e-7), C1, C2) - pressure(lam * (1 - 1e-7), C1, C2)),
                    grid[i], grid[i + 1]) for i in np.flatnonzero(np.diff(np.sign(slope)))]
    found = [lp.values["lam"] for lp in branch.limit_points]
    say(f"C1 = {C1}, C2 = {C2}: limit points at lambda = {[f'{x:.7f}' for x in found]}, closed form "
        f"{[f'{x:.7f}' for x in exact]}; the branch within {worst:.1e} of the curve")
    assert len(found) == len(exact) == (1 if C2 == 0 else 2)
    assert all(abs(a - b) < 1e-6 for a, b in zip(found, exact, strict=True))
    assert worst < 1e-8
    if C2 == 0:
        assert abs(found[0] - 7 ** (1 / 6)) < 1e-6
