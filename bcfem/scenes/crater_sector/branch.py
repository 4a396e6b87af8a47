r"""The critical mode at a bifurcation of the wedge, and the switch onto the bifurcated branch.

At a state near a simple bifurcation the constrained tangent (the Hessian of the Lagrangian,
the multipliers' rows as constraints, the unknowns on the plate and the Dirichlet ones held) has
one eigenvalue of the pencil

    [K  B^T] [v]     [M 0] [v]
    [B  0  ] [l] = mu [0 0] [l]

near zero, M the identity on the free displacement unknowns. Inverse iteration at the shift 0
finds it with one factorisation of the tangent (MUMPS LU of the saddle-point matrix); the
eigenvector is the mode the state leaves the fundamental branch along. Its sign is arbitrary (a
solver's round-off picks it, and so may differ between serial and parallel runs): it is fixed
by the sign of the mode's largest cos(n theta) content on the wall, so every run perturbs the
same way and takes the same branch.
"""

from __future__ import annotations

from dataclasses import dataclass

from petsc4py import PETSc

import numpy as np
import ufl
from dolfinx import fem

from bcfem.geometry.crater_sector import WALL
from bcfem.log import progress
from bcfem.mpi import global_sum, real_value
from bcfem.physics.cavity import Cavity
from bcfem.physics.fluids import over_body
from bcfem.physics.protocols import Term
from bcfem.scenes.crater_sector.model import wall_content


def critical_mode(problem, model, waves, iterations: int = 60, rtol: float = 1e-9):
    """The eigenvector of the constrained tangent of ``problem`` (at its current states) with
    the eigenvalue nearest zero, as one function per state, scaled so that its wall's largest
    Fourier coefficient (``model.wall_fourier`` over ``waves``) is +1 (in crater radii: a
    perturbation delta times it moves the wall by delta a in that mode). Returns (functions,
    eigenvalue mu (per unit displacement squared, over the energy scale), {n: coefficient})
    (collective)."""
    held = problem.held_rows()
    A, _ = problem.jacobian()
    K = A.copy()
    K.zeroRowsColumns(held, diag=1.0)
    functions = [fem.Function(s.function_space) for s in problem.states]
    index = problem.names.index("displacement")
    free = ~problem.constrained("displacement")
    functions[index].x.array[:] = free
    mask = problem.vector_from(functions)
    mask.setValues(held, np.zeros(held.size))
    mask.assemble()
    # a deterministic start, the same on every partition: the wall's radial cos(n theta) for the
    # wedge's lowest n, spread over the body by the coordinates
    X = model.nodes
    n = min(waves)
    radial = X / np.maximum(np.linalg.norm(X, axis=1), 1e-12)[:, None]
    start = np.cos(n * np.arctan2(X[:, 1], X[:, 0]))[:, None] * radial
    for f in functions:
        f.x.array[:] = 0.0
    functions[index].x.array[:] = start.ravel()
    v = problem.vector_from(functions)
    v.pointwiseMult(v, mask)
    ksp = PETSc.KSP().create(problem.comm)
    ksp.setOptionsPrefix(problem.prefix + "critical_mode_")
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    ksp.setOperators(K)
    ksp.setFromOptions()
    w, Kv = v.duplicate(), v.duplicate()
    mu = np.inf
    try:
        for _ in range(iterations):
            v.scale(1.0 / v.norm())
            ksp.solve(v, w)  # the rhs M v: v is zero off the free unknowns
            w.pointwiseMult(w, mask)  # the eigenvector's displacement part
            w.scale(1.0 / w.norm())
            K.mult(w, Kv)
            previous, mu = mu, Kv.dot(w)  # Rayleigh quotient (w is M-orthogonal to the rest)
            w.copy(v)
            if abs(mu - previous) <= rtol * abs(mu):
                break
    finally:
        ksp.destroy()
        for vec in (w, Kv, mask):
            vec.destroy()
        K.destroy()
    problem.functions_from(v, functions)
    v.destroy()
    content = model.wall_fourier(functions[index], waves)
    largest = max(content, key=lambda k: abs(content[k]))
    scale = 1.0 / content[largest]
    for f in functions:
        f.x.array[:] *= scale
    return functions, float(mu), {k: c * scale for k, c in content.items()}


@dataclass(frozen=True)
class DrawnLiquid(Term):
    r"""A liquid of which the fraction r is drawn off, r an unknown (the path's load once the
    wave's amplitude drives it): :math:`-(p - 1)(V(u) - (1 - r) V_0)`, stationary in p: V = (1 - r) V0."""

    cavity: Cavity
    full_volume: float
    pressure_name: str = "fluid_pressure"
    fraction_name: str = "drawn_fraction"
    name = "drawn_liquid"

    @property
    def multipliers(self) -> tuple[str, ...]:
        return (self.pressure_name,)

    def energy(self, ctx) -> ufl.Form:
        p, r = ctx.real_state(self.pressure_name), ctx.real_state(self.fraction_name)
        zero = ctx.constant("liquid_pressure_diagonal", 0.0)  # the diagonals in the pattern
        return -(p - 1.0) * self.cavity.volume(ctx.kin) + over_body(
            ctx, (p - 1.0) * (1.0 - r) * self.full_volume + zero * ((p - 1.0) ** 2 + r**2))


@dataclass(frozen=True)
class WaveAmplitude(Term):
    r"""The wall's cos n theta content held at the run-time constant ``wave_amplitude`` xi by the
    force mu: :math:`\mu\,(c_n(u) - \xi)`, c_n as :meth:`Sector.wall_fourier`'s."""

    waves: int
    norm: float  # the integral of cos^2 n theta over the wall, times the crater radius [mm^3]
    name = "wave_amplitude"
    multipliers = ("wave_force",)

    def energy(self, ctx) -> ufl.Form:
        force, amplitude = ctx.real_state("wave_force"), ctx.constant("wave_amplitude")
        zero = ctx.constant("wave_force_diagonal", 0.0)
        return ctx.kin.surface_integral(force * wall_content(ctx, ctx.u, self.waves) / self.norm, WALL) + over_body(
            ctx, -force * amplitude + zero * force**2)


def wave_branch(model, problem, terms, fraction: float, amplitudes, count, cutbacks: int = 4,
                open_problem=None) -> dict:
    r"""The bifurcated branch from the state of ``problem`` (volume-controlled, the fraction
    ``fraction`` drawn off, just below a bifurcation), followed by its wave's amplitude: the
    critical mode's largest cos n theta content c_n is driven through c_n(start) + ``amplitudes``
    (increasing from 0) and the drawn fraction r is the unknown whose row is mu = 0 (no force
    holds the amplitude: an equilibrium). Through the pitchfork this path is regular, so it
    passes the branch's folds in r and is the same branch on every partition. Each step starts
    from a secant predictor (the first from the critical mode), halved up to ``cutbacks`` times
    if Newton fails. ``count()`` is the unstable modes of the volume-controlled problem at the
    current states (r set first). Returns {"mode": {"mu", "fourier"}, "waves": n, "rows":
    [{"amplitude", "r", "s", "A_over_A0", "F_tilde" (= s A2/A0), "unstable", "fourier"}], "failure"}
    (collective).

    The mesh is not symmetric about theta = pi/2m, so the pitchfork is slightly imperfect: near
    the onset the fundamental branch's own c_n changes by a few 1e-4 a (size 0.1). A first step
    below that can meet the fundamental branch instead, and the secant from there leads astray:
    take the amplitudes' steps well above it (e.g. 0.002)."""
    from bcfem.scenes.crater_sector.onset import standalone

    ctx = model.ctx
    m = model.sector.wedge_waves
    harmonics = [k * m for k in range(5)]
    mode, mu, content = critical_mode(problem, model, harmonics[1:])
    n = max(content, key=lambda k: abs(content[k]))
    ctx.real_state("drawn_fraction").x.array[:] = fraction
    ctx.real_state("wave_force").x.array[:] = 0.0
    liquid = DrawnLiquid(Cavity(WALL), model.crater_volume)
    cos2 = global_sum(fem.form(ctx.kin.surface_integral(ufl.cos(n * ufl.atan2(ctx.kin.x[1], ctx.kin.x[0])) ** 2,
                                                        WALL)))
    wave = WaveAmplitude(n, cos2 * model.sector.crater_radius)
    fixed = ctx.constant("wave_amplitude")
    start = model.wall_fourier(model.u, [n])[n]
    r_state, pressure = ctx.states["drawn_fraction"], ctx.states[liquid.pressure_name]
    force = ctx.states["wave_force"]
    row = ufl.TestFunction(r_state.function_space)
    zero = ctx.constant("drawn_fraction_diagonal", 0.0)  # r's diagonal in the pattern (see DrawnLiquid)
    result = {"mode": {"mu": mu, "fourier": content}, "waves": n, "rows": [], "failure": None}
    with (open_problem or standalone(ctx.mesh.comm))(
            "wave", ctx, [*terms, liquid, wave], model.bcs, {"snes_type": "vinewtonrsls"},
            rows={"drawn_fraction": over_body(ctx, (force + zero * r_state) * row)}, energy_scale=model.energy_scale,
            line_search_fallbacks=("bt",)) as path:
        model.contact_bounds(path)
        index = {name: i for i, name in enumerate(path.names)}
        tangent = [np.zeros_like(s.x.array) for s in path.states]
        tangent[index["displacement"]] = mode[problem.names.index("displacement")].x.array.copy()
        done, saved, pending = 0.0, path.save(), list(amplitudes)
        while pending:
            step = pending[0] - done
            for _ in range(cutbacks + 1):
                for state, base, direction in zip(path.states, saved, tangent):
                    state.x.array[:] = base + step * direction
                fixed.value = start + done + step
                if path.solve():
                    break
                step *= 0.5
            else:
                result["failure"] = f"Newton failed at the amplitude {done + step:g} ({path.failure})"
                path.restore(saved)
                break
            now = path.save()
            tangent = [(a - b) / step for a, b in zip(now, saved)]  # the secant, per unit amplitude
            done, saved = done + step, now
            if np.isclose(done, pending[0], rtol=0, atol=1e-12):
                pending.pop(0)
            r, suction, opening = real_value(r_state), 1 - real_value(pressure), model.opening()
            result["rows"].append({"amplitude": done, "r": r, "s": suction, "A_over_A0": opening,
                                   "F_tilde": suction * opening, "unstable": count(r),
                                   "fourier": model.wall_fourier(model.u, [0, *harmonics[1:]])})
            progress(f"crater sector: wave {n} amplitude {done:.4g}: r = {r:.6g}, s = {result['rows'][-1]['s']:.6g}")
    return result
