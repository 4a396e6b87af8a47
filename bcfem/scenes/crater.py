r"""Scene ``crater``: suction cycle of an air-filled crater pressed on a rigid plate (ch. 7).

Stage 1 (vent open): the platen compresses the specimen to the preload
ε = -ΔL/L; the crater air stays at p_a, so the crater wall is unloaded.
Stage 2 (sealed): the platen retracts until the force on it vanishes; the air
obeys Boyle's law p V = p_a V1, with the pressure a global unknown:

.. math:: L(u, p) = \int W(F, p_s)\,dV - (p - p_a)\,V(u) + p_a V_1 \ln(p/p_a),

V(u) being the current crater volume closed by the plate. A liquid instead
keeps its volume, V = V1 (``--fluid liquid``, ch. 8; :mod:`bcfem.fluids`). The suction force is
F = (1 - V1/V2) p_a A2 (eq. 7.3), F~ = F/(p_a A0) (eq. 7.13).

Units: pressures in p_a (so μ/p_a = β), lengths in mm. The bottom face is held
on the plate (u_z = 0, free to slide): ambient pressure holds the sealed
interface down. The crater wall is in frictionless contact with the plate
(z >= 0, a variational inequality: PETSc's vinewtonrsls); a crater that
closes (V1 = 0) leaves a vacuum.

Past a preload of about 0.15 the crater wall near the rim, and under suction
the whole wall, reaches rubber's creasing strain. Creases have no length scale
of their own, so without one they form at the mesh scale. The wall may not
pass through itself (penalty self-contact, :mod:`bcfem.self_contact`). A surface energy γ on the
crater wall (``surface_energy`` = γ/(μa), default 0.01, physical PDMS 7e-5)
gives creases a length scale; its effect on F~ is measured by halving it
(docs/benchmarks/crater-regulariser.md): the default lowers F~ by 1.4-2.1 % on a
smooth path, and past an instability the same parameters have several stable end
states. Loss of (axisymmetric) stability is detected from the tangent's inertia
after every step; a step Newton cannot reach is
taken by pseudo-time relaxation (a snap), and both are reported. With
``waves`` = N the non-axisymmetric Fourier modes n = 1..N are checked as well
(:mod:`bcfem.modes`): the wave numbers that lose stability, and where, are
reported as ``waves`` events (symmetry breaking). A cycle that fails is traced
once more from the start with Newton steps bounded to keep the wall admissible and
a larger iteration limit (``retraced`` in the summary says why the first failed).
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass

import numpy as np
import ufl
from dolfinx import fem

from bcfem.cavity import Cavity
from bcfem.context import Context
from bcfem.energies import SolidStrain, SolidSurfaceEnergy
from bcfem.fluids import FLUIDS, Vacuum
from bcfem.geometry.crater import AXIS, BOTTOM, CRATER, LAYER, SPECIMEN, TOP, CraterGeometry, create_mesh
from bcfem.log import progress
from bcfem.materials import NearlyIncompressibleNeoHookean
from bcfem.modes import ModeAnalysis
from bcfem.mpi import PointEvaluator, global_sum, real_value
from bcfem.params import require
from bcfem.problem import Problem
from bcfem.relaxation import Viscosity
from bcfem.self_contact import WallSelfContact
from bcfem.solid import AxisymmetricSolid
from bcfem.stepping import LoadPath, SteppingError

SUMMARY = "air-filled crater pressed on a rigid plate: the suction cycle (ch. 7)"
DESCRIPTION = """\
A neo-Hookean specimen (nearly incompressible, Taylor-Hood u-p) with a
spherical-cap crater in its bottom face is pressed on a rigid plate with the
vent open (stage 1), then sealed and unloaded to zero platen force (stage 2);
the air obeys p V = p_a V1.

Units and normalisations:
  pressures      in p_a = 101.325 kPa;  beta = mu / p_a
  lengths        in mm (experiment: specimen 25.40 x 35.13, crater diameter 12.70)
  alpha          = b / a (crater height over base radius), 1 = hemisphere
  preload eps    = -dL / L of the specimen
  V/V0, A/A0     crater volume and projected area over their values at rest
  F_tilde        = F / (p_a A0) = (1 - V1/V2) A2/A0
The wall is in frictionless contact with the plate. surface_energy (gamma over
mu a) on the crater wall regularises creasing; instabilities (the tangent's
inertia) and snaps (steps passed by pseudo-time relaxation) are reported in
summary.json ('stability'). A cycle that is not 'stable' has passed an
instability, and the same parameters can then end in another stable state with
another F_tilde (for the hemisphere, half the --strain-step moves it by 4.4 %
at eps = 0.225 and up to 76 % from eps = 0.35 on): read such an F_tilde as one of
several equilibria; 'bcfem sweep crater --grid strain_step=0.005:0.02:4' shows
their spread (docs/craters.md). On the hemisphere's smooth path the default
surface_energy 0.01 lowers F_tilde by 1.4-2.1 % against none. The wall does not
pass through itself (penalty self-contact).
Non-axisymmetric deformation is not followed, but with --waves N its onset is
detected: Fourier modes with n = 1..N waves around the axis are checked for
stability after every step (events of kind 'waves')."""
HELP = {
    "fluid": "crater fluid: air (ideal gas, p V = p_a V1) or liquid (incompressible, V = V1)",
    "alpha": "crater aspect b/a, in (0, 1]",
    "beta": "mu / p_a, > 0",
    "preload": "eps = -dL/L, in [0, 0.9), or closure (the smallest eps with V1 = 0, eps_m; a crater still "
               "open at eps = 0.85 is reported as such and cycled from there)",
    "kappa_ratio": "bulk over shear modulus, in [10, 1e8]",
    "size_crater": "element size at the crater over a, > 0",
    "specimen_radius": "specimen radius Rs [mm]",
    "specimen_height": "specimen height Hs [mm]",
    "crater_radius": "crater base radius a [mm], < Rs",
    "strain_step": "platen strain between checkpoints of both stages, in (0, 0.1] (failed steps are "
                   "halved; every run passes the same checkpoints)",
    "surface_energy": "gamma / (mu a) of the crater wall, in [0, 0.1]: regularises creasing "
                      "(physical PDMS: 7e-5); it also acts as a surface stress, lowering F_tilde on a "
                      "smooth path (the hemisphere: by 1.4-2.1 per cent at 0.01 against 0, linear in gamma). "
                      "0 is the unregularised model: it gets through Fig. 7.6's preloads too, but "
                      "its creases are as fine as the mesh",
    "layer_thickness": "reinforcement layer lining the crater, alpha' = t / a, 0 (none) or in (0, 0.5)",
    "layer_stiffness": "beta' = mu_layer / mu of the reinforcement, > 0",
    "self_contact": "penalty of the crater wall's self-contact over mu/L (L: node spacing on the wall), "
                    "0 (off) or in [10, 1e4]; the penetration is about the contact pressure over "
                    "self_contact mu, in units of L; a state whose wall passes through itself deeper "
                    "than L/4 is rejected (0 turns that check off too)",
    "max_snaps": "budget of snaps (steps passed by pseudo-time relaxation) per stage, 0 to 1000; a path "
                 "that snaps more often fails (a deepening crease); stiff linings need up to ~20",
    "waves": "check the non-axisymmetric modes with n = 1..waves circumferential waves after every step "
             "(symmetry breaking), 0 (off) to 400",
}
#: ``--preload closure``: load to the smallest preload that closes the crater (eps_m)
CLOSURE = -1.0
#: ``--preload closure`` gives up closing the crater at this preload
MAX_CLOSURE_PRELOAD = 0.85
#: how far beyond its original height the platen may lift looking for zero force
MAX_LIFT = 0.1
#: a crater with V <= CLOSED V0 counts as closed (vacuum inside)
CLOSED = 1e-8
#: ``--preload closure`` stops at V1 <= CLOSURE_VOLUME V0, or once the wall lies on the plate up to
#: within sqrt(CLOSED_AREA) a of the axis with at most TRAPPED_VOLUME V0 left in folds
CLOSURE_VOLUME = 1e-3
CLOSED_AREA = 2.5e-3
TRAPPED_VOLUME = 1e-2
#: full Newton steps can cycle between two contact active sets (seen on unloading at
#: alpha = 1, beta = 5: the residual alternates 3.48 / 3.61); backtracking breaks the cycle
#: there, and where it stalls, a line search along Newton's direction on the energy may (the
#: (0.06, 3) lining's cycle was the self-contact's facing test instead, see self_contact.py)
LINE_SEARCH_FALLBACKS = ("bt", "cp")
#: the retrace of a failed cycle: Newton steps bounded so that the wall stays admissible
#: (a full step through the wall leaves the self-contact's window, and Newton converged with
#: the wall through itself: rejected at (0.06, 100) of Fig. 7.11b) and more iterations (the
#: folded lining of (0.03, 300) stalled with 25 and got through with 80)
CAREFUL = {"snes_max_it": 80}
COLUMNS = ["stage", "eps", "V_over_V0", "p_over_pa", "A_over_A0", "F_tilde", "F_hat"]


@dataclass(frozen=True)
class Params:
    """Parameters of ``crater`` (see HELP for units)."""

    fluid: str = "air"
    alpha: float = 1.0
    beta: float = 47.3 / 101.325
    preload: float = 0.1
    kappa_ratio: float = 1e4
    size_crater: float = 0.06
    specimen_radius: float = 12.70
    specimen_height: float = 35.13
    crater_radius: float = 6.35
    strain_step: float = 0.0125
    surface_energy: float = 0.01
    layer_thickness: float = 0.0
    layer_stiffness: float = 1.0
    self_contact: float = 100.0
    waves: int = 0
    max_snaps: int = 24

    #: solver budgets: they decide whether a path gets through, never where it goes, so a
    #: sweep reuses a solved point whatever its budget (and retries one that ran out)
    BUDGETS = ("max_snaps",)

    CHOICES = {"fluid": list(FLUIDS)}
    WORDS = {"preload": {"closure": CLOSURE}}

    def __post_init__(self):
        require(self.fluid in self.CHOICES["fluid"], f"fluid must be one of {self.CHOICES['fluid']} (got {self.fluid!r})")
        require(self.beta > 0 and math.isfinite(self.beta), f"beta must be > 0 (got {self.beta})")
        require(self.preload == CLOSURE or 0 <= self.preload < 0.9,
                f"preload must be in [0, 0.9) or 'closure' (got {self.preload})")
        require(10 <= self.kappa_ratio <= 1e8, f"kappa-ratio must be in [10, 1e8] (got {self.kappa_ratio})")
        require(0 <= self.surface_energy <= 0.1, f"surface-energy must be in [0, 0.1] (got {self.surface_energy})")
        require(self.layer_thickness == 0 or 0 < self.layer_thickness < 0.5,
                f"layer-thickness (t/a) must be 0 or in (0, 0.5) (got {self.layer_thickness})")
        require(self.layer_stiffness > 0 and math.isfinite(self.layer_stiffness),
                f"layer-stiffness (mu_layer/mu) must be > 0 (got {self.layer_stiffness})")
        require(self.self_contact == 0 or 10 <= self.self_contact <= 1e4,
                f"self-contact must be 0 (off) or in [10, 1e4] (got {self.self_contact})")
        require(self.waves == int(self.waves) and 0 <= self.waves <= 400,
                f"waves must be an integer in [0, 400] (got {self.waves})")
        require(self.max_snaps == int(self.max_snaps) and 0 <= self.max_snaps <= 1000,
                f"max-snaps must be an integer in [0, 1000] (got {self.max_snaps})")
        require(0 < self.strain_step <= 0.1, f"strain-step must be in (0, 0.1] (got {self.strain_step})")
        self.geometry()  # validates alpha, radii and sizes before any meshing

    def geometry(self) -> CraterGeometry:
        return CraterGeometry(radius=self.specimen_radius, height=self.specimen_height,
                              crater_radius=self.crater_radius, alpha=self.alpha,
                              size_crater=self.size_crater, size_far=max(0.5, self.size_crater),
                              layer_thickness=self.layer_thickness * self.crater_radius)


class Crater:
    """The composed crater model: mesh, states, terms, the two stages' problems."""

    def __init__(self, params: Params, comm):
        self.params = params
        geometry = params.geometry()
        self.geometry = geometry
        data = create_mesh(geometry, comm)
        msh, facets = data.mesh, data.facet_tags
        V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
        self.u = fem.Function(V, name="displacement")
        self.ctx = Context(self.u, AxisymmetricSolid(self.u, quadrature_degree=4, cell_tags=data.cell_tags,
                                                     facet_tags=facets))

        def neo_hookean(mu):
            return NearlyIncompressibleNeoHookean(mu=mu, kappa=params.kappa_ratio * mu)

        if params.layer_thickness > 0:  # the layer is its own material region
            self.solids = [SolidStrain(neo_hookean(params.beta), region=SPECIMEN),
                           SolidStrain(neo_hookean(params.layer_stiffness * params.beta), region=LAYER)]
        else:
            self.solids = [SolidStrain(neo_hookean(params.beta))]
        self.platen = fem.Function(V.sub(1).collapse()[0])
        gamma = params.surface_energy * params.beta * geometry.crater_radius  # gamma~ mu a
        self.surface = SolidSurfaceEnergy(gamma, CRATER, "crater_surface_energy") if gamma > 0 else None
        self.viscosity = Viscosity(self.u)
        # the wall (or its lining) must not fold through itself; the stiffest material sets k
        stiffest = params.beta * (max(1.0, params.layer_stiffness) if params.layer_thickness > 0 else 1.0)
        # residuals in units of the stiffest modulus (>= p_a): Newton's round-off floor grows
        # with the stiffness and stalled above the absolute tolerance for beta' = 300 linings
        self.energy_scale = max(1.0, stiffest)
        self.self_contact = (WallSelfContact(facets, CRATER, stiffest, penalty=params.self_contact)
                             if params.self_contact > 0 else None)
        self.strain = 0.0
        self.bcs = self._bcs(V, facets)
        self.cavity = Cavity(CRATER)
        self.volume = fem.form(self.cavity.volume(self.ctx.kin))
        self.rim = PointEvaluator(msh, [geometry.crater_radius, 0.0]).expression(self.u[0])
        Vz, zmap = V.sub(1).collapse()
        _, rmap = V.sub(0).collapse()
        wall = fem.locate_dofs_topological(Vz, 1, facets.find(CRATER))
        self._wall_dofs = wall
        # reference points and displacement dofs of the crater wall, found once
        self._wall = (Vz.tabulate_dof_coordinates()[wall], np.asarray(zmap).reshape(-1)[wall],
                      np.asarray(rmap).reshape(-1)[wall])
        self.mesh = msh
        self.cell_tags = data.cell_tags

    def terms(self, *fluid) -> list:
        """The solid, the wall's surface energy and self-contact (if any), the fluid, and the
        viscosity used only while relaxing past an instability."""
        optional = [t for t in (self.surface, self.self_contact) if t is not None]
        return [*self.solids, *optional, *fluid, self.viscosity]

    def set_platen(self, strain: float) -> None:
        """Platen displacement for the specimen strain eps = -dL/L."""
        self.strain = strain
        self.platen.x.array[:] = -strain * self.params.specimen_height

    def _bcs(self, V, facets):
        def on(sub, tag, value=None):
            space, _ = V.sub(sub).collapse()
            dofs = fem.locate_dofs_topological((V.sub(sub), space), 1, facets.find(tag))
            return fem.dirichletbc(value if value is not None else fem.Function(space), dofs, V.sub(sub))

        return [on(0, AXIS), on(1, BOTTOM), on(1, TOP, self.platen)]

    def observe(self, stage: str, eps: float, V1: float | None = None) -> dict:
        V0, A0 = self.geometry.crater_volume, math.pi * self.geometry.crater_radius**2
        V = global_sum(self.volume)
        A = math.pi * self.open_radius() ** 2
        p = real_value(self.ctx.states["fluid_pressure"]) if "fluid_pressure" in self.ctx.states and V1 else 1.0
        if V1 == 0.0:
            p = 0.0  # closed crater: vacuum
        return {"stage": stage, "eps": eps, "V_over_V0": V / V0, "p_over_pa": p, "A_over_A0": A / A0,
                "F_tilde": (1 - p) * A / A0, "V": V}

    def contact_bounds(self, problem):
        """z = Z + u_z >= 0 on the crater wall (frictionless contact with the plate), as
        bounds of the variational-inequality solver; every other unknown is free."""
        lower = [fem.Function(s.function_space) for s in problem.states]
        upper = [fem.Function(s.function_space) for s in problem.states]
        for f in lower:
            f.x.array[:] = -1e20
        for f in upper:
            f.x.array[:] = 1e20
        V = self.u.function_space
        Vz, zmap = V.sub(1).collapse()
        Z = Vz.tabulate_dof_coordinates()[self._wall_dofs, 1]
        lower[problem.names.index("displacement")].x.array[np.asarray(zmap).reshape(-1)[self._wall_dofs]] = -Z
        problem.set_bounds(lower, upper)

    def wave_check(self, terms, prefix: str):
        """None, or {n: unstable modes with n waves} at the current state, n = 1..``waves``;
        the wall nodes on the plate hold their normal displacement."""
        if not self.params.waves:
            return None
        analysis = ModeAnalysis(self.ctx, [t for t in terms if t is not self.viscosity], self.bcs, prefix)
        X, zdofs, _ = self._wall
        tolerance = 1e-9 * self.geometry.crater_radius

        def check():
            on_plate = zdofs[X[:, 1] + self.u.x.array[zdofs] <= tolerance]
            return analysis.scan(range(1, self.params.waves + 1), held=on_plate)

        return check

    def open_radius(self) -> float:
        """Current radius of the edge of the suction area, where the crater wall leaves
        the plate. The pressure on the wall has the vertical resultant Δp π r_edge²
        whatever the wall's shape above (an overhang cancels), so A = π r_edge².
        The wall lies on the plate from the rim up to some reference height; the edge
        is the rim if only the rim is on the plate, else midway between the highest
        node on the plate and the next node off it (known to within a node spacing)."""
        X, zdofs, rdofs = self._wall
        a = self.geometry.crater_radius
        z = X[:, 1] + self.u.x.array[zdofs]
        r = X[:, 0] + self.u.x.array[rdofs]
        on = z <= 1e-6 * a
        Z = X[:, 1]  # the reference height orders the wall from the rim (0) to the pole
        local_on = max(zip(Z[on], r[on]), default=(-1.0, 0.0))
        top, r_on = max(self.mesh.comm.allgather(local_on))
        above = ~on & (Z > top)
        local_off = min(zip(Z[above], r[above]), default=(math.inf, 0.0))
        nearest, r_off = min(self.mesh.comm.allgather(local_off))
        if top <= 1e-12 * a or not math.isfinite(nearest):
            return r_on
        return 0.5 * (r_on + r_off)


def solve(params: Params, comm, model_class: type[Crater] = Crater) -> tuple[list[dict], dict]:
    """Run both stages; returns (rows, summary).

    A cycle that fails is traced again from the start with a more careful Newton
    (:data:`CAREFUL`), which is slower and takes other paths where full steps did not
    fail; a cycle that gets through the first time is never changed by it. The summary's
    ``retraced`` then says why the first trace failed.

    Args:
        model_class: ``Crater`` or a subclass (e.g. one that records the deformed states,
            :mod:`bcfem.scenes.crater_frames`); the cycle itself is the same.
    """
    t0 = time.perf_counter()
    try:
        return _cycle(params, comm, model_class, t0, careful=False)
    except SteppingError as failure:
        if params.self_contact == 0:
            raise
        progress(f"{failure}: tracing the cycle again with bounded Newton steps")
        try:
            rows, summary = _cycle(params, comm, model_class, t0, careful=True)
        except SteppingError as again:
            raise SteppingError(f"{again} (traced again with bounded Newton steps; the first trace: "
                                f"{failure})", again.reached) from None
        summary["retraced"] = str(failure)
        return rows, summary


def _cycle(params: Params, comm, model_class: type[Crater], t0: float, careful: bool) -> tuple[list[dict], dict]:
    from scipy.optimize import brentq

    model = model_class(params, comm)
    H = params.specimen_height
    multipliers = ["solid_pressure", "fluid_pressure"]
    relax_stiffness = params.beta / model.geometry.crater_radius**2  # mu / a^2
    events: list[dict] = []

    set_platen = model.set_platen
    # stage 1: vent open
    rows = [model.observe("load", 0.0)]
    vi = {"snes_type": "vinewtonrsls", **(CAREFUL if careful else {})}
    loading = Problem(model.ctx, model.terms(), model.bcs, "bcfem_crater_load_", vi, energy_scale=model.energy_scale,
                      line_search_fallbacks=LINE_SEARCH_FALLBACKS)
    model.contact_bounds(loading)
    if careful:
        loading.bound_steps()
    path = LoadPath(loading, set_platen, "load", model.viscosity, relax_stiffness, multipliers, events=events,
                    max_snaps=params.max_snaps, waves=model.wave_check(model.terms(), "bcfem_crater_load_modes_"))
    path.start()
    try:
        closes = params.preload == CLOSURE
        if closes:
            preload, closes = _load_to_closure(model, path, rows, params)
        else:
            preload = params.preload
            _through(path, 0.0, preload, params.strain_step, lambda e: rows.append(model.observe("load", e)))
    finally:
        loading.close()
    V1 = rows[-1]["V"]
    # full closure: nothing left inside (closure mode neglects a trapped remnant <= CLOSURE_VOLUME V0)
    closed = V1 <= CLOSED * model.geometry.crater_volume or closes
    if closed and params.fluid == "liquid":
        # an incompressible liquid crater that closed stays closed: V2 = V1 = 0, F = 0 (eq. 8.8)
        final = {**model.observe("unload", preload, 0.0), "p_over_pa": 1.0, "F_tilde": 0.0, "A_over_A0": 0.0}
        return _finish(params, model, rows, final, V1, closed, preload, preload, events, comm, t0, path.unstable)
    if not closed:
        model.ctx.real_state("fluid_pressure").x.array[:] = 1.0
    fluid = Vacuum(model.cavity) if closed else FLUIDS[params.fluid](model.cavity, V1)

    # stage 2: sealed, the platen retracts until its force vanishes
    terms = model.terms(fluid)
    unloading = Problem(model.ctx, terms, model.bcs, "bcfem_crater_unload_", vi, energy_scale=model.energy_scale,
                        line_search_fallbacks=LINE_SEARCH_FALLBACKS)
    model.contact_bounds(unloading)
    if careful:
        unloading.bound_steps()
    # self-contact is left out: its forces pair up on the wall, so their work in w is the
    # contact force times gap / H, negligible
    lagrangian = unloading.lagrangian
    w = fem.Function(model.u.function_space)
    w.interpolate(lambda x: np.vstack([0 * x[0], x[1] / H]))
    platen_force = fem.form(ufl.derivative(lagrangian, model.u, w))  # compression < 0
    waves = model.wave_check(terms, "bcfem_crater_unload_modes_")
    path = LoadPath(unloading, set_platen, "unload", model.viscosity, relax_stiffness, multipliers, events=events,
                    max_snaps=params.max_snaps, waves=waves)
    V1_sealed = 0.0 if closed else V1
    try:
        path.start()
        if closed:  # the suction of a closed crater jumps from 0 to p_a: ramp it at fixed platen
            ramp = model.ctx.constant("vacuum_load")
            sealing = LoadPath(unloading, lambda s: setattr(ramp, "value", s), "seal", model.viscosity,
                               relax_stiffness, multipliers, events=events, max_snaps=params.max_snaps,
                               waves=waves)
            sealing.start()
            first = len(events)
            sealing.advance(0.0, 1.0, 0.25)
            for event in events[first:]:  # report the platen strain; the ramp value goes in the detail
                event.update(detail=f"{event['detail']} (vacuum ramp at {event['eps']:.3g})", eps=preload)
            path.unstable, path.unstable_waves = sealing.unstable, sealing.unstable_waves
        path.set_load(preload)
        last = path.mark(preload)

        def accept(strain):
            if global_sum(platen_force) >= 0:
                return True
            rows.append(model.observe("unload", strain, V1_sealed))
            last.update(path.mark(strain))
            return False

        # past a snap the specimen can still push at eps = 0: the platen then lifts further
        # a force below round-off counts as zero: at eps = 0 there is nothing to unload
        round_off = -1e-10 * math.pi * params.specimen_radius**2 * max(1.0, params.beta)
        if global_sum(platen_force) >= round_off:
            reached = preload
        else:
            reached = _through(path, preload, -MAX_LIFT, params.strain_step, accept)
        if global_sum(platen_force) < round_off:
            raise SteppingError(f"unload: the platen force is still compressive at eps = {reached:.4g}", reached)
        if reached < 0:
            events.append({"stage": "unload", "eps": reached, "kind": "lift", "unstable": None,
                           "detail": "zero platen force only beyond the specimen's original height"})
        zero_force = reached
        if reached != last["value"]:
            def force_at(strain):
                # always from the last state before the zero: no hysteresis between evaluations
                start = path.rewind(last)
                path.advance(start, strain, abs(strain - start))
                return global_sum(platen_force)

            zero_force = brentq(force_at, reached, last["value"], xtol=1e-10 * max(preload, 1e-3))
            force_at(zero_force)
    finally:
        final = model.observe("unload", model.strain, V1_sealed)
        unloading.close()
    return _finish(params, model, rows, final, V1, closed, preload, zero_force, events, comm, t0, path.unstable)


def _through(path, start: float, end: float, step: float, on_accept) -> float:
    """Advance from ``start`` to ``end`` through the checkpoints k * step, so that every run
    passes the same load states whatever its final preload (sweep points share one path).
    Stops early when ``on_accept`` returns True; returns the last accepted value."""
    sign = 1.0 if end >= start else -1.0
    k = math.floor(start / step + 1e-9) + 1 if sign > 0 else math.ceil(start / step - 1e-9) - 1
    current, stopped = start, [False]

    def accept(value):
        stopped[0] = bool(on_accept(value)) if on_accept else False
        return stopped[0]

    while (end - current) * sign > 1e-12 and not stopped[0]:
        checkpoint = k * step
        target = checkpoint if (end - checkpoint) * sign > 1e-12 else end
        current = path.advance(current, target, abs(target - current), accept)
        k += int(sign)
    return current


def _finish(params, model, rows, final, V1, closed, preload, zero_force, events, comm, t0,
            final_unstable: int) -> tuple[list[dict], dict]:
    """The summary of a cycle (and the last row); ``final_unstable``: the unstable axisymmetric
    modes of the final state (> 0: F is that of an unstable equilibrium, a saddle)."""
    rows.append(final)
    geometry = model.geometry
    for row in rows:
        row["F_hat"] = row["F_tilde"] / params.beta
    summary = {
        "F_tilde": final["F_tilde"], "F_hat": final["F_tilde"] / params.beta,
        "V1_over_V0": V1 / geometry.crater_volume,
        "V2_over_V0": final["V_over_V0"], "p2_over_pa": final["p_over_pa"], "A2_over_A0": final["A_over_A0"],
        "preload": preload, "eps_at_zero_force": zero_force,
        # the fluid's equation of state at the end of stage 2: p V = V1 (air), V = V1 (liquid)
        "fluid_law_residual": 0.0 if closed else
        (final["p_over_pa"] if params.fluid == "air" else 1.0) * final["V"] / V1 - 1,
        "eps_closure": _first_closure(rows, geometry.crater_volume),
        "eps_m": preload if params.preload == CLOSURE and closed else None,
        "closure_note": _closure_note(params, closed, preload, V1 / geometry.crater_volume, final["V_over_V0"]),
        "stability": classify(events),
        "final_unstable_modes": final_unstable,
        "retraced": None,  # why the first trace failed, if this is the second (see solve)
        "symmetry_breaking": symmetry_breaking(events) if params.waves else None,
        "stability_waves": classify([e for e in events if e.get("breaks_symmetry")]) if params.waves else None,
        "instabilities": events,
        "surface_energy": params.surface_energy,
        "gas_permeation": permeation_estimate(1 - final["p_over_pa"], geometry.crater_radius)
        if params.fluid == "air" else None,
        "dofs": sum(s.function_space.dofmap.index_map.size_global * s.function_space.dofmap.index_map_bs
                    for s in model.ctx.states.values()),
        "ranks": comm.size, "wall_time_s": time.perf_counter() - t0, "parameters": asdict(params),
    }
    for row in rows:
        row.pop("V")
    return rows, summary


def _closure_note(params, closed: bool, preload: float, V1_over_V0: float, V2_over_V0: float) -> str | None:
    """What closure means for this cycle's force (None: an open crater at a given preload)."""
    if not closed:
        return f"does not close up to eps = {preload:g}: the cycle runs from there" \
            if params.preload == CLOSURE else None
    note = ("closed on loading: an incompressible liquid crater stays closed, F = 0 (eq. 8.8)"
            if params.fluid == "liquid" else "closed on loading: vacuum inside, F = p_a A2 (eq. 7.17)")
    if V1_over_V0 > CLOSED:
        note += f"; a trapped remnant V1 = {V1_over_V0:.2g} V0 is neglected"
    if params.fluid == "air" and V2_over_V0 <= CLOSURE_VOLUME:
        # the vacuum holds the flattened wall on the plate (a soft or shallow crater)
        note += (f"; it stays closed after unloading (V2 = {V2_over_V0:.2g} V0): no cavity, so A2 and "
                 f"F are ~0 (the force to peel a closed crater off the plate is not this measure)")
    return note


def classify(events) -> str:
    """``stable``, ``unstable-unloading`` (only on unloading) or ``unstable-both`` (already on
    loading), from the inertia events and snaps of a cycle (or from the symmetry-breaking
    events alone: ``stability_waves``)."""
    def unstable(event):
        return event["kind"] == "snap" or (event["unstable"] or 0) > 0 or event.get("breaks_symmetry", False)

    if any(unstable(e) for e in events if e["stage"] == "load"):
        return "unstable-both"
    if any(unstable(e) for e in events):
        return "unstable-unloading"
    return "stable"


def symmetry_breaking(events) -> dict:
    """{stage: the first eps where more modes with n waves than axisymmetric ones are unstable,
    and those n}, for the stages where it happens (needs ``waves``)."""
    first = {}
    for e in events:
        if e["kind"] == "waves" and e["breaks_symmetry"] and e["stage"] not in first:
            first[e["stage"]] = {"eps": e["eps"], "waves": e["waves"]}
    return first


def _load_to_closure(model, path, rows, params, bisections: int = 10) -> tuple[float, bool]:
    """Stage 1 up to the smallest preload that closes the crater, eps_m (to a 2^-bisections
    fraction of the last step, or to the bracket where a snap-through closure stops the
    bisection): load until the crater is closed, then bisect between the last open and
    the first closed state. Closed: V1 <= ``CLOSURE_VOLUME`` V0, or the wall
    lies on the plate up to the axis (A1 <= ``CLOSED_AREA`` A0) with at most
    ``TRAPPED_VOLUME`` V0 left in pockets (a wall that folds onto the plate, e.g. a thin
    stiff layer, traps pockets that never close). Stage 2 neglects the remnant, which
    changes F by at most V1/V2; the summary reports V1.

    Returns (eps_m, True), or (``MAX_CLOSURE_PRELOAD``, False) for a crater still open there
    (a result, e.g. a thick stiff lining that holds it open: the cycle then runs from there)."""
    max_preload = MAX_CLOSURE_PRELOAD
    V0 = model.geometry.crater_volume

    def closed(row) -> bool:
        return row["V"] <= CLOSURE_VOLUME * V0 or (row["V"] <= TRAPPED_VOLUME * V0
                                                    and row["A_over_A0"] <= CLOSED_AREA)

    open_state = path.mark(0.0)

    def accept(eps):
        row = model.observe("load", eps)
        rows.append(row)
        if closed(row):
            return True
        open_state.update(path.mark(eps))
        return False

    closed_at = _through(path, 0.0, max_preload, params.strain_step, accept)
    if not closed(rows[-1]):
        return closed_at, False
    closed_state = path.mark(closed_at)
    for _ in range(bisections):
        low = path.rewind(open_state)
        mid = 0.5 * (low + closed_at)
        try:
            path.advance(low, mid, mid - low)
        except SteppingError:
            # the crater snaps shut inside the bracket and Newton cannot follow: eps_m is
            # known to within the bracket [low, closed_at]
            break
        row = model.observe("load", mid)
        if closed(row):
            closed_at, closed_state = mid, path.mark(mid)
            rows[-1] = row
        else:
            open_state = path.mark(mid)
    path.rewind(closed_state)
    return closed_at, True


def _first_closure(rows, V0: float) -> float | None:
    """The first accepted loading strain with V = 0 (to 1e-8 V0), or None."""
    closed = [r["eps"] for r in rows if r["stage"] == "load" and r["V"] <= CLOSED * V0]
    return min(closed) if closed else None


def permeation_estimate(pressure_drop: float, crater_radius_mm: float, unload_time_s: float = 200.0,
                        wall_mm: float = 6.0) -> dict:
    """Upper bound of the relative air leakage J/V0 during unloading (eqs. 7.19-7.21).

    CO2/PDMS Henry permeability 22.4 L/mol x 2e-12 mol/(m s Pa), times 3 for the
    30:1 curing ratio; A/V0 = 3/a for the hemisphere; T = 20 C; the pressure drop
    is this run's (the dissertation takes 0.2 atm, and a = 6.35 mm: its '0.635 mm'
    is a typo).
    """
    permeability = 3 * 22.4e-3 * 2e-12  # [m^3 (STP) m / (m^2 s Pa)]
    drop = pressure_drop * 101325.0
    area_over_volume = 3.0 / (crater_radius_mm * 1e-3)
    ratio = (293.15 / 273.15) * drop * permeability * area_over_volume * unload_time_s / (wall_mm * 1e-3)
    return {"J_over_V0": ratio, "pressure_drop_pa": drop, "note": "upper bound, eqs. 7.19-7.21"}


def plot(rows, summary):
    """The cycle: crater volume, pressure and suction against the platen strain."""
    from bcfem.plots import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.4))
    for stage, style in (("load", "-o"), ("unload", "-s")):
        part = [r for r in rows if r["stage"] == stage]
        eps = [r["eps"] for r in part]
        for ax, key, label in zip(axes, ("V_over_V0", "p_over_pa", "F_tilde"), ("V/V0", "p/p_a", "F~")):
            ax.plot(eps, [r[key] for r in part], style, ms=3, label=stage)
            ax.set_xlabel("platen strain ε")
            ax.set_ylabel(label)
    axes[2].set_title(f"F~ = {summary['F_tilde']:.4g} (preload {summary['parameters']['preload']:g})", fontsize=9)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    return fig


def sweep_point(params: Params, comm) -> dict:
    """One point of ``bcfem sweep crater``: the cycle's end values."""
    _, summary = solve(params, comm)
    point = {k: summary[k] for k in ("F_tilde", "F_hat", "V1_over_V0", "V2_over_V0", "p2_over_pa", "A2_over_A0",
                                     "eps_at_zero_force", "preload", "eps_m", "stability", "final_unstable_modes")}
    point["stability_code"] = STABILITY.index(summary["stability"])  # a number for contour maps
    point["retraced"] = summary["retraced"] is not None
    if params.waves:
        point["stability_waves"] = summary["stability_waves"]
        point["symmetry_code"] = STABILITY.index(summary["stability_waves"])
    return point


#: the stability classes, in the order of ``stability_code``
STABILITY = ["stable", "unstable-unloading", "unstable-both"]


#: What ``bcfem sweep crater`` computes and plots (one axis: a curve per column).
SWEEP = {"solve": sweep_point,
         "maps": [("F_tilde", "F~"), ("F_hat", "F^ = F/(mu A0)"), ("V1_over_V0", "V1/V0"),
                  ("V2_over_V0", "V2/V0"), ("p2_over_pa", "p2/p_a"), ("A2_over_A0", "A2/A0"),
                  ("preload", "eps (eps_m for --preload closure)"),
                  ("stability_code", "0 stable, 1 unstable on unloading, 2 on loading too"),
                  ("symmetry_code", "symmetry breaking (--waves): 0 none, 1 on unloading, 2 on loading too")],
         "title": "suction cycle"}
