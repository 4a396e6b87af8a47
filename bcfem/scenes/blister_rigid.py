r"""Scene ``blister-rigid``: a liquid-filled membrane blister on a rigid substrate.

Free energy (eq. 3.42 without adhesion), in units of :math:`\mu_f t_0 R_0^2`
with lengths in units of the blister radius :math:`R_0`:

.. math:: \Pi = \int t_0 W(I_1)\,dA - \Delta p\,V + \gamma_l A,
   \qquad dA = 2\pi R\,dR,\ R\in[0, 1].

Normalised outputs: :math:`P = \Delta p R_0/(\mu_f t_0)`,
:math:`\alpha = \gamma_l/(\mu_f t_0)`, :math:`V_0 = 4\pi R_0^3/3`,
aspect :math:`= z(0)/R_0`, contact angle :math:`= \pi - \phi_0^-`
(the angle between the membrane and the substrate at the edge), energy
:math:`= \Pi/(\pi R_0^2\mu_f t_0)`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace

import numpy as np
import ufl
from dolfinx import fem

from bcfem.columns import SHARED, Column, declare
from bcfem.kinematics.membrane import AxisymmetricMembrane
from bcfem.mpi import PointEvaluator, cell_maximum, coordinate_range, sample
from bcfem.params import Bound, ContinuationParams, check_bounds, describe, require
from bcfem.path.continuation import Switch
from bcfem.path.terminations import AnyOf, Reaches
from bcfem.physics.context import Context
from bcfem.physics.energies import MembraneStrain, PressureVolume, SurfaceTension
from bcfem.physics.materials import MATERIALS, Gent, NeoHookean
from bcfem.physics.observables import Integral, Measured, Observable, RealState, cavity_volume, pressure, row
from bcfem.physics.protocols import Term, total_energy
from bcfem.radial_profile import RadialProfile, check_resolved, shape_of
from bcfem.radial_profile import parse as parse_profile
from bcfem.run.scene import BranchScene
from bcfem.scenes.membrane_edges import EDGES, Edge, domain
from bcfem.theory.membrane import droplet, droplet_angle_from_volume, simple_membrane_pressure

V0 = 4.0 * math.pi / 3.0  # reference volume 4/3 pi R0^3, with R0 = 1

SUMMARY = "membrane blister on a rigid substrate, clamped edge (ch. 3)"
DESCRIPTION = """\
An inflated incompressible hyperelastic membrane (neo-Hookean or Gent),
clamped at radius R0 on a rigid substrate, filled with a liquid whose
interface with the membrane has tension gamma_l. The free energy is
Pi = U_f - dp V + gamma_l A (eq. 3.42 without adhesion); the pressure is a
global unknown traced by arc-length continuation, through its limit points.

Units and normalisations (all inputs and outputs are dimensionless):
  lengths        by R0 (blister radius)
  P              = dp R0 / (mu_f t0)
  alpha          = gamma_l / (mu_f t0)
  V/V0           with V0 = 4/3 pi R0^3
  aspect         = z(0) / R0
  contact angle  = pi - phi0 (membrane vs substrate at the edge), degrees
  energy         = Pi / (pi R0^2 mu_f t0)
Outputs: DIR/branch.csv, DIR/summary.json, DIR/pv.png, DIR/fields.bp (VTX)."""
HELP = {
    "material": "strain-energy function",
    "Jm": "Gent locking limit of I1-3 (Gent only)",
    "alpha": "elasto-capillary number gamma_l/(mu_f t0)",
    "v_max": "end of the branch, V/V0",
    "v_start": "start of the branch, V/V0 < v-max",
    "cells": "cells across R0",
    "degree": "Lagrange degree of the displacement",
    "stiffness": "membrane stiffness mu_f t0 relative to the unit (small: the droplet limit)",
    "edge": "edge condition: clamped, sliding (free radial slip, Young angle phi-Y), "
            "adhesive (delamination when it lowers the free energy)",
    "phi_Y_deg": "Young angle of the liquid on the substrate [deg] (sliding edge)",
    "adhesion": "(gamma_ls - dgamma)/(mu_f t0), cost of debonding per area (adhesive, slippery); "
                "negative: debonding releases energy (Figs. 3.15-3.16 map [-10, 20]); with --edge adhesive "
                "also a profile of the substrate's radius r/R0 as blister-soft's --delta-gamma takes it "
                "(step:R_s:inner:outer[:width], ramp:..., table:FILE[:width]; width >= 2 cells at R1 = R0)",
    "outer_radius": "outer material radius n of the film, in R0 (slippery edge)",
    "far_field": "(gamma_s - dgamma)/(mu_f t0) = N_r at the outer radius (slippery edge)",
    "stop_radius": "also end the branch when the debond radius R1/R0 reaches this (inf: never)",
    "start_volume": "V/V0 where the path starts and is traced both ways; 0: v-start "
                    "(1 for the sliding edge, whose small-volume end is wrapped; "
                    "0.3 for the slippery edge)",
}
COLUMNS = declare("V_over_V0", "P", "aspect", "contact_angle_deg", "energy", "R1_over_R0", "r1_over_R0", "s")
#: measured in every row, not written to branch.csv (guards, events and summaries read them)
N_THETA_MIN = Column("N_theta_min", "mu_f t0", "the least hoop tension (< 0: where wrinkling can start, Fig. 3.19)")
DPI_DR1 = Column("dPi_dR1", "pi mu_f t0 R0", "the free energy's derivative in the debond radius (a moving front)")


@dataclass(frozen=True)
class Params:
    """Parameters of ``blister-rigid`` (all normalised by mu_f, t0 and R0).

    Attributes:
        material: 'neo-hookean' or 'gent'.
        Jm: Gent locking limit of I1 - 3, > 0 (ignored for neo-Hookean).
        alpha: elasto-capillary number gamma_l/(mu_f t0), >= 0.
        v_max: the branch ends at V/V0 = v_max, > v_start.
        v_start: the branch starts near this V/V0 (tiny, > 0).
        cells: cells across the blister radius, >= 2.
        degree: Lagrange degree of the displacement, 1..4.
        stiffness: membrane modulus factor mu_f t0 in units of the reference (1);
            small values approach the droplet limit.
        continuation: step control.
    """

    material: str = field(default="gent", metadata=describe(HELP["material"], choices=sorted(MATERIALS)))
    Jm: float = field(default=100.0, metadata=describe(HELP["Jm"], bound=Bound(1e-2, 1e6)))
    alpha: float = field(default=0.0, metadata=describe(HELP["alpha"], bound=Bound(0, 1e8)))
    v_max: float = field(default=6.0, metadata=describe(HELP["v_max"], bound=Bound(0, 1e3, open_low=True)))
    v_start: float = field(default=0.01, metadata=describe(HELP["v_start"],
                                                           bound=Bound(0, 1e3, open_low=True, open_high=True)))
    cells: int = field(default=200, metadata=describe(HELP["cells"], bound=Bound(2, 20_000, integer=True)))
    degree: int = field(default=2, metadata=describe(HELP["degree"], bound=Bound(1, 4, integer=True)))
    stiffness: float = field(default=1.0, metadata=describe(HELP["stiffness"], bound=Bound(1e-8, 1e6)))
    edge: str = field(default="clamped", metadata=describe(HELP["edge"], choices=sorted(EDGES)))
    phi_Y_deg: float = field(default=135.0, metadata=describe(HELP["phi_Y_deg"],
                                                              bound=Bound(0, 180, open_low=True, open_high=True)))
    adhesion: float | RadialProfile = field(
        default=2.5, metadata={"parse": parse_profile, **describe(HELP["adhesion"], bound=Bound(-1e8, 1e8))})
    outer_radius: float = field(default=4.0, metadata=describe(HELP["outer_radius"],
                                                               bound=Bound(1, 1e3, open_low=True, open_high=True)))
    far_field: float = field(default=0.0, metadata=describe(HELP["far_field"], bound=Bound(-1e8, 1e8)))
    stop_radius: float = field(default=math.inf, metadata=describe(
        HELP["stop_radius"], bound=Bound(1, 1e3, open_low=True, also=(math.inf,))))
    start_volume: float = field(default=0.0, metadata=describe(HELP["start_volume"], bound=Bound(0, 1e3)))
    continuation: ContinuationParams = field(default_factory=lambda: ContinuationParams(ds_max=0.1))


    def __post_init__(self):
        check_bounds(self)
        require(self.material in MATERIALS,
                f"--material must be one of {sorted(MATERIALS)} (got {self.material!r})")
        require(self.edge in EDGES, f"--edge must be one of {sorted(EDGES)} (got {self.edge!r})")
        require(self.v_start < self.v_max, f"need --v-start < --v-max (got {self.v_start}, {self.v_max})")
        if isinstance(self.adhesion, RadialProfile):
            require(self.edge == "adhesive", f"--adhesion takes a profile with --edge adhesive only (got {self.edge})")
            check_resolved(self.adhesion, 1 / self.cells, "--adhesion", f"at R1 = R0 (--cells {self.cells})")
        require(self.start_volume == 0 or self.v_start <= self.start_volume < self.v_max,
                f"--start-volume must be 0 or in [v-start, v-max) (got {self.start_volume})")

    @property
    def start_at(self) -> float:
        """V/V0 of the first converged point."""
        if self.start_volume > 0:
            return self.start_volume
        # the sliding and slippery edges pull the membrane in at small volume; a plain
        # cap guess there converges to a compressed state, not to the wrapped branch
        above = {"sliding": 1.0, "slippery": 0.3}.get(self.edge)
        return max(self.v_start, min(above, 0.5 * self.v_max)) if above else self.v_start

    def material_model(self):
        if self.material == "gent":
            return Gent(mu=self.stiffness, Jm=self.Jm)
        return NeoHookean(mu=self.stiffness)


#: Parameters that only set run-time constants (``fem.Constant``) or Python-side settings of the
#: path (ends, step control, start, scales): a composed :class:`Model` takes new values of them
#: without compiling (:func:`scene_for`); alpha only while > 0 (0 leaves its term out).
RUN_TIME = ("alpha", "adhesion", "phi_Y_deg", "far_field", "v_max", "v_start", "stop_radius",
            "start_volume", "continuation")


def structure(params: Params) -> tuple:
    """What a composed :class:`Model` depends on: every parameter but the :data:`RUN_TIME`
    ones, and whether there is surface tension at all (hashable; equal keys, same model)."""
    fixed = sorted((f.name, getattr(params, f.name)) for f in fields(params) if f.name not in RUN_TIME)
    return (*fixed, ("surface_tension", params.alpha > 0), ("adhesion_profile", shape_of(params.adhesion)))


@dataclass
class Model:
    """The compiled part of the blister: mesh, states, terms, edge and observables."""

    ctx: Context
    terms: list
    edge: Edge
    observe: Callable[[], dict]
    switches: list
    structure: tuple  # of the parameters it was composed for


def compose(params: Params, comm, extra_terms=()) -> Model:
    """Mesh, terms, edge conditions and observables of the blister (the forms they compile).

    Args:
        params: validated parameters; only their :func:`structure` counts here.
        comm: the MPI communicator of the mesh.
        extra_terms: energy terms of a research script, added to the free
            energy (and to the reported energy) like the built-in ones.
    """
    msh, cell_tags = domain(params, comm)
    V = fem.functionspace(msh, ("Lagrange", params.degree, (2,)))
    u = fem.Function(V, name="displacement")
    ctx = Context(u)
    edge = EDGES[params.edge](ctx, params)
    ctx.kin = AxisymmetricMembrane(u, quadrature_degree=2 * params.degree + 2, reference=edge.reference,
                                   cell_tags=cell_tags)
    terms: list[Term] = [MembraneStrain(params.material_model())]
    if params.alpha > 0:
        terms.append(SurfaceTension(params.alpha, region=edge.liquid_region))
    terms.append(PressureVolume())
    terms.extend(edge.terms)
    terms.extend(extra_terms)
    switches = []
    if edge.free is not None:
        # Griffith, no healing: the edge moves once the energy release rate -dPi/dR1 turns positive
        switches.append(Switch("delamination onset", lambda values: -values["dPi_dR1"],
                               lambda: setattr(edge.free, "value", 1.0), grows="debond_radius"))
    return Model(ctx, terms, edge, observables(ctx, terms), switches, structure(params))


def scene_for(model: Model, params: Params) -> BranchScene:
    """The blister of ``params`` on a composed model: its run-time constants set and its
    states put back as composed, so that the scene traces as a newly built one does.

    Raises:
        ValueError: ``params`` need another model (their :func:`structure` differs).
    """
    require(structure(params) == model.structure,
            "the model was composed for parameters that differ in more than blister_rigid.RUN_TIME")
    ctx = model.ctx
    for term in model.terms:
        if isinstance(term, SurfaceTension):
            ctx.set(term.name, params.alpha)
    model.edge.reset(ctx, params)

    def start(fraction: float = 1.0) -> float:
        return cap_guess(ctx, params, fraction * params.start_at)

    return BranchScene(name="blister-rigid", ctx=ctx, terms=model.terms, bcs=model.edge.bcs, load="pressure",
                 start=start, observe=model.observe,
                 end=AnyOf((Reaches("V_over_V0", params.v_max), Reaches("R1_over_R0", params.stop_radius)))
                 if math.isfinite(params.stop_radius) else Reaches("V_over_V0", params.v_max),
                 begin=(lambda values: params.v_start - values["V_over_V0"])
                 if params.start_at > params.v_start else None,
                 grows="V_over_V0",
                 progress_keys=("V_over_V0", "P", "aspect"), fields=[ctx.u],
                 # an adhesion profile folds the branch where the front meets a step (held, then
                 # released): a correction that lands beyond the fold is refused, the step halved
                 continuation=replace(params.continuation, max_correction=min(1.0, params.continuation.max_correction))
                 if isinstance(params.adhesion, RadialProfile) else params.continuation,
                 plots={"pv.png": ("V_over_V0", "P", "V/V0", "P = Δp R0/(μ t0)")},
                 # membrane pressures are O(stiffness), a droplet's O(2 alpha)
                 load_scale=max(params.stiffness, 2 * params.alpha),
                 guard=guard_for(params), rows=model.edge.rows, switches=model.switches,
                 summarize=summarize, params=params, columns=COLUMNS)


def build(params: Params, comm, *, extra_terms=()) -> BranchScene:
    """The blister of ``params``: :func:`compose` (see its arguments), then :func:`scene_for`."""
    return scene_for(compose(params, comm, extra_terms), params)


def summarize(branch) -> dict:
    """``delamination_onset``: where the edge started to move, or None; and
    ``hoop_compression``: where the hoop traction first turns compressive, or None.

    At the onset the clamped and the propagated states are the same state, so
    their free energies agree; both are reported as a consistency check
    (the clamped one from the last held point, the propagated one from the
    first free point, which the continuation reaches by re-solving).
    """
    compressed = [row for row in branch.rows if row["N_theta_min"] < 0]
    hoop = {"hoop_compression": None if not compressed else {
        "first_V_over_V0": compressed[0]["V_over_V0"],
        "N_theta_min": min(row["N_theta_min"] for row in compressed),
        "note": "N_theta < 0: the membrane may wrinkle there (not modelled)"}}
    onset = next((e for e in branch.events if e["name"] == "delamination onset"), None)
    if onset is None:
        return {"delamination_onset": None, **hoop}
    after = next(row for row in branch.rows if row["s"] >= onset["s"])
    return {"delamination_onset": {"V_over_V0": onset["V_over_V0"], "P": onset["P"],
                                   "energy_clamped": onset["energy"], "energy_propagated": after["energy"]},
            **hoop}


def guard_for(params: Params):
    """Stop with a clear message when the membrane leaves the physical range:
    a Gent membrane locking (I1 - 3 -> Jm), or a volume that is not positive
    (the membrane would pass through the rigid substrate)."""

    def guard(values):
        if values["P"] < -1e-3 * max(params.stiffness, params.alpha):  # ~0 is a flat, slack blister
            return (f"negative pressure (P = {values['P']:.6g} at V/V0 = {values['V_over_V0']:.6g}): the path "
                    f"is on a compressed branch; start it at a larger volume with --start-volume "
                    f"(e.g. 0.3 for the slippery edge, 1 for the sliding edge)")
        if values["V_over_V0"] <= 0:
            return (f"the blister volume is not positive (V/V0 = {values['V_over_V0']:.3g}, "
                    f"P = {values['P']:.6g}): the membrane would pass through the substrate")
        if params.material == "gent" and values["I1_minus_3_max"] > 0.99 * params.Jm:
            return (f"the Gent membrane is locking: max(I1 - 3) = {values['I1_minus_3_max']:.6g} "
                    f"reached 0.99 Jm (Jm = {params.Jm:g}) at V/V0 = {values['V_over_V0']:.6g}, "
                    f"P = {values['P']:.6g}, before v-max = {params.v_max:g}; lower v-max or raise Jm")
        return None

    return guard


def membrane_tractions(ctx, terms):
    """(N_r, N_theta) of every membrane strain term among ``terms``, summed (a research script's
    second strain energy adds its tractions)."""
    pairs = [t.tractions(ctx) for t in terms if isinstance(t, MembraneStrain)]
    if not pairs:
        raise LookupError("the blister's terms hold no MembraneStrain")
    return sum(p[0] for p in pairs), sum(p[1] for p in pairs)


def observables(ctx, terms) -> Callable[[], dict]:
    """The blister's observables (compiled once); returns their collective row."""
    kin, u = ctx.kin, ctx.u
    apex = PointEvaluator(ctx.mesh, [0.0]).expression(u[1])
    # just inside the blister zone: with the slippery edge the slope jumps at the front
    edge_slope = PointEvaluator(ctx.mesh, [1.0 - 1e-10]).expression(ufl.as_vector([kin.dr, kin.dz]))
    edge_radius = PointEvaluator(ctx.mesh, [1.0]).expression(kin.r)
    degree = ctx.u.function_space.element.basix_element.degree
    I1 = cell_maximum(ctx.mesh, kin.I1 - 3, degree)
    _, hoop = membrane_tractions(ctx, terms)
    hoop_compression = cell_maximum(ctx.mesh, -hoop, degree)

    def contact_angle() -> float:
        dr, dz = edge_slope()
        return math.degrees(math.atan2(-dz, dr))

    measures: list[Observable] = [
        cavity_volume(kin.integral(kin.volume_density), V0),
        pressure(ctx.real_state("pressure")),
        Measured(SHARED["aspect"], lambda: float(apex()[0])),
        Measured(SHARED["contact_angle_deg"], contact_angle),
        Integral.of("energy", total_energy(ctx, terms), math.pi),
        Measured(SHARED["I1_minus_3_max"], I1),
        Measured(N_THETA_MIN, lambda: -hoop_compression()),
        RealState(SHARED["R1_over_R0"], ctx.states["debond_radius"]) if "debond_radius" in ctx.states
        else Measured(SHARED["R1_over_R0"], lambda: 1.0),
        Measured(SHARED["r1_over_R0"], lambda: float(edge_radius()[0])),
    ]
    if "debond_radius" in ctx.states:  # the configurational force on the front
        R1 = ctx.states["debond_radius"]
        one = fem.Function(R1.function_space)
        one.x.array[:] = 1.0
        measures.append(Integral.of(DPI_DR1, ufl.derivative(total_energy(ctx, terms), R1, one), math.pi))
    return lambda: row(measures)


def cap_guess(ctx, params: Params, v_over_v0: float) -> float:
    """Set u to a spherical cap of volume V/V0; return a pressure guess.

    The cap sits on the unit base, except for the sliding edge, whose base
    radius follows from a contact angle between the membrane's 90 degrees and
    Young's angle, weighted by stiffness and surface tension. Material points
    are spread uniformly along the arc (a uniform meridian stretch), which also
    covers caps steeper than a hemisphere. A flat membrane has no tension, so
    Newton cannot start there.
    """
    young = {"sliding": params.phi_Y_deg,
             "slippery": math.degrees(math.acos(-params.adhesion / params.alpha))
             if params.edge == "slippery" and not isinstance(params.adhesion, RadialProfile)
             and 0 < params.alpha and abs(params.adhesion) < params.alpha
             else None}.get(params.edge)
    if young is not None:
        weight = params.alpha / (params.alpha + params.stiffness)
        theta = math.radians(90.0 + weight * (young - 90.0))
        base = (v_over_v0 / float(droplet(theta)[2])) ** (1.0 / 3.0)
    else:
        theta, base = droplet_angle_from_volume(v_over_v0), 1.0
    rho = base / math.sin(theta)
    outer = params.outer_radius

    def cap(x):
        xi = np.minimum(x[0], 1.0)
        shape = np.vstack([rho * np.sin(theta * xi) - xi, rho * (np.cos(theta * xi) - math.cos(theta))])
        bonded = x[0] > 1.0  # the slippery edge's film: flat, its front moved with the cap's base
        R = 1.0 + (outer - 1.0) * (x[0] - 1.0)
        shape[0, bonded] = base + (outer - base) * (x[0][bonded] - 1.0) - R[bonded]
        shape[1, bonded] = 0.0
        return shape

    ctx.u.interpolate(cap)
    # the membrane part from the simple theory (capped: membrane pressures stay O(2 mu t0 / R0)),
    # the surface-tension part from Laplace
    membrane = min(float(simple_membrane_pressure(v_over_v0)), 2.0) * params.stiffness
    return membrane + 2.0 * params.alpha * math.sin(theta) / base


def profile(scene, samples: int = 201) -> dict:
    """The deformed profile on every rank at ``samples`` points evenly spaced in the mesh
    coordinate: reference R, current (r, z), and the tractions N_r, N_theta (collective).

    The fields are interpolated once into a discontinuous space of the
    displacement's degree (exact for R, r, z; interpolated for the tractions,
    one-sided at element edges) and evaluated with one search tree.
    """
    ctx = scene.ctx
    kin = ctx.kin
    N_r, N_t = membrane_tractions(ctx, scene.terms)
    degree = ctx.u.function_space.element.basix_element.degree
    W = fem.functionspace(ctx.mesh, ("DG", degree, (5,)))
    fields = fem.Function(W)
    fields.interpolate(fem.Expression(ufl.as_vector([kin.R, kin.r, kin.z, N_r, N_t]),
                                      W.element.interpolation_points))
    lo, hi = coordinate_range(ctx.mesh)
    xi = np.linspace(lo, hi, samples)
    # just inside the ends (the axis value of N is a limit)
    points = np.zeros((samples, 3))
    points[:, 0] = np.clip(xi, lo + 1e-12, hi - 1e-12)
    values = sample(fields, points)
    # on the axis (R = 0) the hoop stretch r/R is a limit: take the nearest finite value
    for column in values.T:
        bad = ~np.isfinite(column)
        if bad.any() and (~bad).any():
            column[bad] = np.interp(np.flatnonzero(bad), np.flatnonzero(~bad), column[~bad])
    keys = ("R", "r", "z", "N_r", "N_theta")
    return {"xi": xi, **{k: values[:, i] for i, k in enumerate(keys)}}
