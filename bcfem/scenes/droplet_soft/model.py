r"""The droplet-soft model: substrate mesh, terms, boundary conditions, observables, solve.

Linear (§5.2, eq. 5.26):

.. math:: \Pi = \int W_{lin}(\varepsilon, p)\,dV + \sum_{wet, dry} \tfrac{\gamma}{2}\int (\partial_R u_z)^2 dA
          - \gamma_l\sin\theta\,2\pi R_0 u_z(R_0) + \tfrac{2\gamma_l\sin\theta}{R_0}\int_{wet} u_z\,dA
          + f_t\,2\pi R_0 u_r(R_0),

one linear solve (stage ``solve``). Neo-Hookean (§5.3):

.. math:: L = \int W(F, p_s)\,dV + \gamma_{ls}A_{wet} + \gamma_s A_{dry} + \gamma_l A_{cap} - p\,(V - V_0),

every tension ramped by the load factor from 0 to 1 (stage ``load``, adaptive steps).

The axis has u_r = 0, the base Z = -H is bonded (u = 0) and the far rim R = L R0 slides
(u_r = 0). The tip's angles are measured with chords to the surface points at R0 ± δ
(δ = two contact-element sizes) and R0 ± 4δ, extrapolated to δ → 0: the solid's (cusp)
angle between the wetted and the dry chord, the liquid's between the wetted chord and the
cap, the vapour's between the cap and the dry chord; they sum to 360°.

``control = "neumann"`` (the dissertation's iteration, §5.4.2) then changes the drop's volume
(a bracket, then a root) until the liquid pulls along the resultant of the two solid tensions at the tip
(the δ chords): the perpendicular part of γl v + γls τ_ls + γs τ_s vanishes, and φl and the
volume are outputs. The magnitude's part stays as the bulk's share (``neumann_residual``).
"""

from __future__ import annotations

import math

import numpy as np
from dolfinx import fem

from bcfem.geometry.substrate import AXIS, BOTTOM, FAR, OUTER_TOP, WETTED, create_mesh
from bcfem.mpi import PointEvaluator, real_value, sample
from bcfem.path.stepping import LoadPath, SteppingError
from bcfem.path.terminations import Described, Reaches
from bcfem.physics import bcs as dirichlet
from bcfem.physics.context import Context
from bcfem.physics.energies import SolidStrain, SolidSurfaceEnergy
from bcfem.physics.linear_solid import LinearDropLoads, LinearElasticity, LinearSurfaceTension, SubstrateKinematics
from bcfem.physics.materials import NearlyIncompressibleNeoHookean
from bcfem.physics.sessile_drop import SphericalCapDrop, cap_volume
from bcfem.run.stages import Ended, Stage, StagedScene
from bcfem.scenes.droplet_soft.params import COLUMNS, Params

#: the three tensions' run-time constants and the Params fields of their targets
TENSIONS = {"gamma_l": "gamma_l", "gamma_s": "gamma_s", "gamma_ls": "gamma_ls"}


def neumann_angles(gamma_s: float, gamma_l: float, gamma_ls: float) -> dict:
    """The angles (degrees) of the solid, liquid and vapour wedges of Neumann's triangle,
    γl v + γls τ_ls + γs τ_s = 0: each phase's angle lies between its two interfaces."""
    def wedge(a, b, opposite):
        return math.degrees(math.acos(max(-1.0, min(1.0, (opposite**2 - a**2 - b**2) / (2 * a * b)))))

    if min(gamma_s, gamma_l, gamma_ls) <= 0:
        return {"solid": None, "liquid": None, "vapour": None}
    return {"solid": wedge(gamma_ls, gamma_s, gamma_l), "liquid": wedge(gamma_ls, gamma_l, gamma_s),
            "vapour": wedge(gamma_l, gamma_s, gamma_ls)}


def profile_radii(width: float) -> np.ndarray:
    """Reference radii R/R0 of the written surface profile, graded towards R0."""
    near = np.logspace(-4, np.log10(0.5), 40)
    return np.unique(np.concatenate([np.linspace(0.0, width, 401), 1.0 - near, 1.0 + near, [1.0]]))


class DropletSoft(StagedScene):
    """The droplet-soft scene: its model, and one stage (:meth:`plan`): ``solve`` (linear) or
    ``load`` (the neo-Hookean substrate, the drop's tension ramped to full)."""

    params: Params
    name = "droplet-soft"
    stages = ("solve", "load")
    columns = COLUMNS

    def __init__(self, params: Params, comm):
        self.params = params
        self.comm = comm
        p = params
        geometry = p.geometry()
        data = create_mesh(geometry, comm)
        mesh, facets = data.mesh, data.facet_tags
        self.mesh = mesh
        V = fem.functionspace(mesh, ("Lagrange", p.degree, (2,)))
        self.u = fem.Function(V, name="displacement")
        kin = SubstrateKinematics(self.u, quadrature_degree=2 * p.degree + 1, facet_tags=facets)
        self.ctx = Context(self.u, kin)
        self.theta_young = p.rest_angle
        pressure_degree = p.degree - 1
        if p.model == "linear":
            pull = math.cos(self.theta_young) if p.contact_force == "liquid" else 0.0
            self.terms = [LinearElasticity(nu=p.nu, pressure_degree=pressure_degree),
                          LinearSurfaceTension(p.gamma_ls, WETTED, "gamma_ls"),
                          LinearSurfaceTension(p.gamma_s, OUTER_TOP, "gamma_s"),
                          LinearDropLoads(p.gamma_l, self.theta_young, 1.0, WETTED, pull)]
            self.drop = None
        else:
            self.volume = cap_volume(1.0, self.theta_young)
            self.drop = SphericalCapDrop(p.gamma_l, self.volume, 1.0, WETTED)
            self.terms = [SolidStrain(NearlyIncompressibleNeoHookean(mu=1.0, kappa=p.kappa), None, pressure_degree),
                          SolidSurfaceEnergy(p.gamma_ls, WETTED, "gamma_ls"),
                          SolidSurfaceEnergy(p.gamma_s, OUTER_TOP, "gamma_s"),
                          self.drop]
        for term in self.terms:  # create every state and constant now, in the same order on every rank
            term.energy(self.ctx)
        if self.drop is not None:
            self.ctx.real_state("cap_slope").x.array[:] = math.tan(self.theta_young / 2)
        self.bcs = [dirichlet.component(V, 0, facets.find(AXIS)),
                    dirichlet.component(V, 0, facets.find(FAR)),
                    dirichlet.component(V, 0, facets.find(BOTTOM)),
                    dirichlet.component(V, 1, facets.find(BOTTOM))]
        # chords to R0 ± δ for the tip's angles: two contact elements, on the finest mesh
        self.delta = 2 * geometry.element_size(0.0)
        points = np.array([[1.0, 0.0, 0.0], [1.0 - self.delta, 0.0, 0.0], [1.0 + self.delta, 0.0, 0.0],
                           [1.0 - 4 * self.delta, 0.0, 0.0], [1.0 + 4 * self.delta, 0.0, 0.0]])
        self._tip_points = points
        self._tip = PointEvaluator(mesh, (1.0, 0.0)).expression(self.u)
        self.profile: list[dict] = []
        self.energy_scale = max(p.gamma_l, p.gamma_s, p.gamma_ls)

    # -- load and observables -----------------------------------------------------------------
    def set_load(self, load: float) -> None:
        for name, field in TENSIONS.items():
            self.ctx.set(name, load * getattr(self.params, field))

    def cap_angle(self) -> float:
        """The cap's angle at the contact line (radians): Young's for the linear model."""
        if self.drop is None:
            return self.theta_young
        return 2.0 * math.atan(real_value(self.ctx.real_state("cap_slope")))

    def _wedges(self, x: np.ndarray, wet: int, dry: int, theta: float) -> np.ndarray:
        """The solid, liquid and vapour wedge angles (radians) of the chords from the tip
        x[0] to the surface points x[wet] and x[dry], and the cap at angle θ."""
        a_wet, a_dry = (math.atan2(*(x[k] - x[0])[::-1]) for k in (wet, dry))
        a_liq = math.pi - theta  # the cap's tangent (-cos θ, sin θ)
        return np.array([(a_dry - a_wet) % (2 * math.pi), (a_wet - a_liq) % (2 * math.pi),
                         (a_liq - a_dry) % (2 * math.pi)])

    def tip_angles(self) -> dict:
        """The tip's position and its three wedge angles (degrees), and the residual of the
        force balance γl v + γls τ_ls + γs τ_s over the largest tension (collective).

        The chord angles at δ and 4δ are extrapolated to δ → 0 assuming an error ∝ δ^{1/2}
        (observed at the neo-Hookean cusp: ``docs/results.md``), A = 2 A(δ) - A(4δ); the
        angles of the δ chords are reported as ``*_chord_deg``."""
        x = self._tip_points[:, :2] + sample(self.u, self._tip_points)
        theta = self.cap_angle()
        near, far = self._wedges(x, 1, 2, theta), self._wedges(x, 3, 4, theta)
        misfit = self._misfit(x, theta)
        solid, liquid, vapour = 2 * near - far
        # the extrapolated directions: the wet chord turned by the liquid wedge from the cap
        a_liq = math.pi - theta
        a_wet, a_dry = a_liq + liquid, a_liq - vapour
        p = self.params
        balance = p.gamma_l * np.array([math.cos(a_liq), math.sin(a_liq)]) \
            + p.gamma_ls * np.array([math.cos(a_wet), math.sin(a_wet)]) \
            + p.gamma_s * np.array([math.cos(a_dry), math.sin(a_dry)])
        return {"tip_r": float(x[0, 0]), "tip_z": float(x[0, 1]),
                "cusp_angle_deg": math.degrees(solid), "liquid_angle_deg": math.degrees(liquid),
                "vapour_angle_deg": math.degrees(vapour),
                "cusp_angle_chord_deg": math.degrees(near[0]), "liquid_angle_chord_deg": math.degrees(near[1]),
                "vapour_angle_chord_deg": math.degrees(near[2]),
                "neumann_residual": float(np.linalg.norm(balance)) / max(p.gamma_l, p.gamma_s, p.gamma_ls),
                "neumann_misfit": misfit}

    def _misfit(self, x: np.ndarray, theta: float) -> float:
        """The part of γl v + γls τ_ls + γs τ_s normal to v, over γl, with τ along the δ chords
        (the resolved tip): zero when the liquid pulls along the solid tensions' resultant."""
        p = self.params
        a_liq = math.pi - theta
        normal = np.array([-math.sin(a_liq), math.cos(a_liq)])
        chords = [(x[k] - x[0]) / np.linalg.norm(x[k] - x[0]) for k in (1, 2)]
        return float((p.gamma_ls * chords[0] + p.gamma_s * chords[1]) @ normal) / p.gamma_l

    def observe(self, load: float, iterations: int) -> dict:
        """The row of ``branch.csv`` at ``load`` (collective)."""
        p = self.params
        _, u_z = self._tip()
        gamma_l = load * p.gamma_l
        nu = p.nu if p.model == "linear" else 0.5
        pressure = (real_value(self.ctx.real_state("drop_pressure")) if self.drop is not None
                    else 2 * gamma_l * math.sin(self.theta_young))
        return {"load": load, "gamma_l": gamma_l, "ridge_height": float(u_z),
                "ridge_height_normalised": float(u_z) / ((1 - nu) * gamma_l) if gamma_l > 0 else math.nan,
                "cap_angle_deg": math.degrees(self.cap_angle()), **self.tip_angles(),
                "laplace_pressure": pressure / gamma_l if gamma_l > 0 else math.nan,
                "drop_volume": self.drop_volume(), "newton_iterations": iterations}

    def drop_volume(self) -> float:
        """The drop's volume over R0³ (the constraint's value; nan for the linear model)."""
        return self.ctx.value("drop_volume") if self.drop is not None else math.nan

    def set_volume(self, volume: float) -> None:
        self.ctx.set("drop_volume", volume)

    def surface_profile(self) -> list[dict]:
        """The top surface at the profile radii (collective): reference R, current r and z,
        and the displacement, all over R0."""
        radii = profile_radii(self.params.width)
        points = np.zeros((radii.size, 3))
        points[:, 0] = radii
        u = sample(self.u, points)
        return [{"R_over_R0": float(R), "r": float(R + ur), "z": float(uz), "u_r": float(ur), "u_z": float(uz)}
                for R, (ur, uz) in zip(radii, u)]

    # -- the scene contract -------------------------------------------------------------------
    @property
    def model(self):
        """The scene is its own model (its context, terms and conditions)."""
        return self

    @property
    def problem_options(self) -> dict:
        return dict(energy_scale=self.energy_scale)

    def setup(self, run) -> None:
        run.watch([self.u])

    def plan(self) -> list[Stage]:
        if self.params.model == "linear":
            return [Stage("solve", terms=lambda: self.terms, drive=self._solve_linear,
                          until=Described("one linear solve"))]
        full = Reaches("load", 1.0)
        return [Stage("load", enter=self._unloaded, terms=lambda: self.terms, drive=self._load,
                      until=full if self.params.control != "neumann" else
                      Described(f"{full}, then the drop volume that zeroes the Neumann misfit"))]

    def _unloaded(self, run) -> None:
        self.set_load(0.0)

    def _solve_linear(self, problem, run) -> Ended:
        try:
            if not problem.solve():
                raise SteppingError(f"solve: the linear system did not converge ({problem.failure})", 0.0)
            run.record(self.observe(1.0, problem.iterations))
        finally:
            self._finish(run)
        return Ended("solved")

    def _load(self, problem, run) -> Ended:
        path = LoadPath(problem, self.set_load, "load", check_stability=False, load_name="load")
        path.start()
        run.record(self.observe(0.0, 0))
        try:
            path.through(0.0, 1.0, self.params.load_step,
                         lambda load: run.record(self.observe(load, problem.iterations)))
            if self.params.control == "neumann":
                self._hold_neumann(run, problem)
                return Ended(f"the Neumann misfit is zero at the drop volume {self.drop_volume():.6g} R0^3")
        finally:
            self._finish(run)
        return Ended("full load")

    def _hold_neumann(self, run, problem, factor: float = 0.85, steps: int = 14) -> None:
        """The drop volume at full load where ``neumann_misfit`` changes sign: march the volume by
        ``factor`` (down if the misfit is negative: a smaller φl turns it up) until it brackets a
        root, then find it with every evaluation starting from the bracket's first state (the tip
        admits more than one state at one volume, so the path to a state is kept the same)."""
        path = LoadPath(problem, self.set_volume, "load", check_stability=False, load_name="drop_volume")
        path.start()
        volume, misfit = self.drop_volume(), run.rows[-1]["neumann_misfit"]
        scale = factor if misfit < 0 else 1.0 / factor
        for _ in range(steps):
            if misfit == 0:
                return
            before = path.mark(volume)
            trial = volume * scale
            path.advance(volume, trial, abs(trial - volume))
            row = self.observe(1.0, problem.iterations)
            run.record(row)
            if math.copysign(1, row["neumann_misfit"]) != math.copysign(1, misfit):
                found = path.root(before, trial, lambda: self._tip_misfit(), xtol=1e-9 * trial)
                row = self.observe(1.0, problem.iterations)
                run.record(row)
                if abs(row["neumann_misfit"]) > 1e-6:  # a sign change without a zero: two tip states
                    raise SteppingError(f"--control neumann: the misfit jumps through zero at the volume {found:.6g} "
                                        f"R0^3 (left at {row['neumann_misfit']:.2e}): the tip has two states "
                                        "there, and no volume zeroes it", 1.0)
                return
            volume, misfit = trial, row["neumann_misfit"]
        raise SteppingError(f"--control neumann: the misfit keeps its sign ({misfit:.2e}) down to the volume "
                            f"{volume:.4g} R0^3", 1.0)

    def _tip_misfit(self) -> float:
        x = self._tip_points[:, :2] + sample(self.u, self._tip_points)
        return self._misfit(x, self.cap_angle())

    def _finish(self, run) -> None:
        """Summary entries and the profile of the last accepted state (also after a failure)."""
        p = self.params
        self.profile = self.surface_profile()
        last = run.rows[-1] if run.rows else None
        if last is None:
            return
        keys = ("ridge_height", "ridge_height_normalised", "cusp_angle_deg", "liquid_angle_deg", "vapour_angle_deg",
                "cusp_angle_chord_deg", "liquid_angle_chord_deg", "vapour_angle_chord_deg", "neumann_residual",
                "cap_angle_deg", "laplace_pressure", "tip_r", "tip_z", "neumann_misfit", "drop_volume")
        run.results.update({k: last[k] for k in keys})
        run.results.update({
            "load_reached": last["load"],
            "young_angle_deg": math.degrees(p.young_angle),
            "rest_angle_deg": math.degrees(self.theta_young),
            "neumann_angles_deg": neumann_angles(p.gamma_s, p.gamma_l, p.gamma_ls),
            "tip_chord": self.delta, "control": p.control,
            "rest_volume": cap_volume(1.0, self.theta_young) if self.drop is not None else None,
            "c": p.c if p.model == "linear" else None})
        if p.model == "linear" and p.gamma_s == p.gamma_ls and p.gamma_s > 0:
            from bcfem.theory import ridge

            theory = ridge.ridge_height(p.c, p.nu, self.theta_young, p.thickness or None) * p.gamma_l
            run.results["ridge_height_theory"] = theory
            run.results["ridge_height_error"] = (last["ridge_height"] - theory) / abs(theory)

    def tables(self, rows, summary) -> dict[str, list[dict]]:
        """``profile.csv``: the top surface at the last accepted state."""
        return {"profile.csv": self.profile}

    def figures(self, rows, summary) -> dict:
        from bcfem.scenes.droplet_soft.report import profile_figure

        return {"profile.png": profile_figure(self.profile, self.params, summary)}
