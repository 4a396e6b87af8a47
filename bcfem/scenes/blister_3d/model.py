r"""The three-dimensional blister: a membrane on its flat reference outline, clamped along
it, inflated at a pressure traced by arc-length (the terms of ``blister-rigid`` on
:class:`bcfem.kinematics.planar_membrane.PlanarMembrane` kinematics).

Over the debonded region Ω (the outline, or the adhesive front's region):

.. math:: \Pi = \int_\Omega t_0 W(I_1)\,dA - \Delta p\,V + \gamma_l\int_\Omega da
          + \int_\Omega (\gamma_{ls} - \Delta\gamma(X))\,dA,

W the Gent, neo-Hookean or Mooney-Rivlin density of the incompressible membrane (relaxed
where it wrinkles, with ``--wrinkles relaxed``), da the current area, the last term the cost of
the debonded substrate (adhesive outlines only)."""

from __future__ import annotations

import math
from operator import itemgetter

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem

from bcfem.geometry.outline import EDGE, create_mesh
from bcfem.kinematics.planar_membrane import PlanarMembrane
from bcfem.log import progress
from bcfem.mpi import cell_maximum, global_sum
from bcfem.path.branch import Switch
from bcfem.physics import observables
from bcfem.physics.context import Context
from bcfem.physics.energies import MembraneStrain, PressureVolume, SurfaceTension, WettedSubstrate
from bcfem.physics.materials import slopes
from bcfem.physics.observables import Integral, Measured, Observable, cavity_volume, row
from bcfem.physics.protocols import total_energy
from bcfem.run.stages import Ended
from bcfem.scenes.blister_3d.growth import FrontGrowth, MeshMotion
from bcfem.scenes.blister_3d.mirrored import create_mirrored_mesh
from bcfem.scenes.blister_3d.params import ADHESIVE_COLUMNS, CLAMPED_COLUMNS, V0, Params
from bcfem.scenes.blister_3d.pattern import Map, MappedWetting, PatternedWetting, values_of, varies
from bcfem.scenes.blister_3d.pattern import at as dgamma_at
from bcfem.scenes.blister_3d.release import ReleaseRate
from bcfem.scenes.blister_3d.report import MembraneScene
from bcfem.scenes.blister_3d.start import FopplStart


def build(params: Params, comm, extra_terms=()) -> MembraneScene:
    """The blister of ``params`` (see :mod:`bcfem.scenes.blister_3d.params`); ``--mesh mirrored``:
    on a mesh symmetric about both axes (:mod:`bcfem.scenes.blister_3d.mirrored`)."""
    data = (create_mirrored_mesh if params.mesh == "mirrored" else create_mesh)(params.geometry(), comm)
    msh = data.mesh
    V = fem.functionspace(msh, ("Lagrange", params.degree, (3,)))
    u = fem.Function(V, name="displacement")
    ctx = Context(u)
    ctx.kin = PlanarMembrane(u, quadrature_degree=2 * params.degree + 2, relaxed=params.wrinkles == "relaxed")
    edge_facets = data.facet_tags.find(EDGE)
    fdim = msh.topology.dim - 1
    bcs = [fem.dirichletbc(np.zeros(3), fem.locate_dofs_topological(V, fdim, edge_facets), V)]
    strain = MembraneStrain(params.material_model())
    tension = SurfaceTension(params.alpha) if params.alpha > 0 else None
    terms = [strain, *([tension] if tension else [])]
    terms.append(PressureVolume())
    adhesive = params.edge == "adhesive"
    patterned = varies(params.delta_gamma)
    wetting = None
    if adhesive:  # the liquid's share of the substrate, pi r^2 for the circle: its cost w per area
        delta = params.delta_gamma
        wetting = (MappedWetting(params.gamma_ls, delta) if isinstance(delta, Map) else
                   PatternedWetting(params.gamma_ls, delta) if patterned else WettedSubstrate(params.adhesion_cost))
        terms.append(wetting)
    terms.extend(extra_terms)

    guess = FopplStart(V, edge_facets)

    def start(fraction: float = 1.0) -> float:
        """u: the Föppl membrane's shape at V/V0 = fraction v-start; returns its pressure."""
        return guess.apply(u, fraction * params.v_start * V0, tension=params.alpha)

    kin = ctx.kin
    pressure = ctx.real_state("pressure")
    degree = params.degree
    I1 = cell_maximum(msh, kin.I1 - 3, degree)
    stretch = cell_maximum(msh, kin.principal_stretches()[0], degree)
    heights = V.sub(2).collapse()[1]  # the z components in u.x.array
    W1, W2 = slopes(ctx.parameters(strain.material), kin.taut_I1, kin.I2)
    alpha = ctx.parameters(tension).gamma if tension else 0.0
    N1, N2 = (N + alpha for N in kin.principal_tensions(W1, dW_dI2=W2))
    compression = cell_maximum(msh, -N2, degree)
    wrinkled = fem.form(kin.integral(ufl.conditional(ufl.lt(N2, 0), 1.0, 0.0) / kin.reference_area))
    measures = fem.Function(V, name="measures")
    direction = fem.Function(V, name="tension_direction")
    tensions = fem.Function(V, name="tensions")
    drawn = [(f, fem.Expression(e, V.element.interpolation_points))
             for f, e in ((measures, ufl.as_vector([*kin.principal_stretches(), N2])),
                          (direction, kin.tension_direction()),
                          (tensions, ufl.as_vector([N1, N2, ufl.sqrt(N1**2 - N1 * N2 + N2**2)])))]

    scale = params.alpha + params.gamma_ls - float(np.mean(values_of(params.delta_gamma)))
    cost = ((lambda points: params.alpha + params.gamma_ls - dgamma_at(params.delta_gamma, points)) if patterned
            else params.adhesion_cost + params.alpha)
    release = None
    if adhesive:  # Pi with the pressure's work -p V (under volume control the target is no energy)
        work = kin.integral(-pressure * kin.volume_density)
        release = ReleaseRate(ctx, total_energy(ctx, [t for t in terms if not isinstance(t, PressureVolume)]) + work,
                              edge_facets, cost, scale)

    column = {c.name: c for c in ADHESIVE_COLUMNS}
    observed: list[Observable] = [
        cavity_volume(kin.integral(kin.volume_density), V0),
        observables.pressure(pressure),
        Measured(column["aspect"], lambda: msh.comm.allreduce(float(u.x.array[heights].max(initial=-np.inf)),
                                                              op=MPI.MAX)),
        Integral.of("energy", total_energy(ctx, terms), math.pi),
        Measured(column["stretch_max"], stretch),
        Measured(column["I1_minus_3_max"], I1),
        Measured(column["N2_min"], lambda: -compression()),
        Integral(column["wrinkled_fraction"], wrinkled),
    ]
    if release:  # the debonded area: the membrane's, whose outline moves with the front
        area = fem.form(kin.integral(1.0))
        observed.append(Measured(column["R_front"], lambda: math.sqrt(global_sum(area) / math.pi)))

    def observe() -> dict:
        for f, expression in drawn:
            f.interpolate(expression)
        return {**row(observed), **(release() if release else {})}

    def end(values) -> float:
        """V/V0 reaches v_max, or (an adhesive edge) the front's onset."""
        # the adhesive edge's branch ends at the onset (the front then moves: grow), or, if it is
        # not to move, where all of the outline is over-critical
        last = "excess_max" if params.front_steps else "excess_min"
        return max(values["V_over_V0"] - params.v_max, values[last] if release else -math.inf)

    # where the release rate first reaches the cost somewhere (the onset) and on average (a front
    # that moves uniformly: the circle's axisymmetric onset); they change nothing
    events = (("delamination onset", "excess_max"), ("uniform onset", "excess_mean"))
    switches = [Switch(name, itemgetter(key), lambda: None) for name, key in events] if release else []
    fronts = []

    def grow(problem, run) -> Ended:
        """The stage ``front``: after the onset, move the front to equilibrium at front_steps
        volumes up to v-max."""
        assert release is not None, "a front grows on an adhesive edge"
        motion = MeshMotion(release, edge_facets, moved=wetting.refresh if isinstance(wetting, MappedWetting) else None)
        start, s0 = run.results["delamination_onset"]["V_over_V0"], run.rows[-1]["s"]
        fronts.append((start, release.gather()[0]))
        growth = FrontGrowth(ctx, problem, release, motion, params.size)
        for k in range(1, params.front_steps + 1):
            target = start + (params.v_max - start) * k / params.front_steps
            growth.settle(target * V0)
            row = {**observe(), "front_residual": growth.residual, "s": s0 + target - start}
            run.record(row)
            fronts.append((target, release.gather()[0]))
            progress(f"front {k:3d}  moves={growth.moves}  " + "  ".join(
                f"{key}={row[key]:.6g}" for key in ("V_over_V0", "P", "R_front", "front_R_min", "front_R_max")))
        front = {"moves": growth.moves, "stiffness": growth.stiffness, "wave": growth.wave,
                 **{key: run.rows[-1][key] for key in ("V_over_V0", "P", "R_front", "front_R_min", "front_R_max")}}
        return Ended(f"the front grew to V/V0 = {run.rows[-1]['V_over_V0']:.6g}", {"front": front})

    def guard(values):
        if values["V_over_V0"] <= 0:
            return (f"the blister volume is not positive (V/V0 = {values['V_over_V0']:.3g}, "
                    f"P = {values['P']:.6g}): the membrane would pass through the substrate")
        if params.material == "gent" and values["I1_minus_3_max"] > 0.99 * params.Jm:
            return (f"the Gent membrane is locking: max(I1 - 3) = {values['I1_minus_3_max']:.6g} reached "
                    f"0.99 Jm (Jm = {params.Jm:g}) at V/V0 = {values['V_over_V0']:.6g}; lower --v-max or raise --Jm")
        return None

    return MembraneScene(name="blister-3d", ctx=ctx, terms=terms, bcs=bcs, load="pressure", start=start,
                 observe=observe, end=end, grows="V_over_V0",
                 progress_keys=("V_over_V0", "P", "aspect", *(("G_max", "G_min") if release else ())),
                 fields=[u, measures, direction, tensions], release=release, switches=switches,
                 after=grow if release and params.front_steps else None, fronts=fronts,
                 follow=params.follow == "broken",
                 summarize=(lambda branch: onset(branch, scale)) if release else None,
                 continuation=params.continuation,
                 plots={"pv.png": ("V_over_V0", "P", "V/V0", "P = Δp R0/(μ t0)")},
                 load_scale=max(1.0, 2 * params.alpha), guard=guard, params=params,
                 columns=ADHESIVE_COLUMNS if adhesive else CLAMPED_COLUMNS)


def onset(branch, cost: float) -> dict:
    """``delamination_onset`` (where the release rate first reaches the cost on the outline, and
    where) and ``uniform_onset`` (where its mean does), or None each. An onset that ends the
    branch is its last row (the end wins over an event in the same step)."""
    events = {event["name"]: event for event in branch.events}
    last = branch.rows[-1]
    for name, key in (("delamination onset", "excess_max"), ("uniform onset", "excess_mean")):
        if name not in events and abs(last[key]) <= 1e-6 * cost:
            events[name] = last
    keys = {"delamination onset": ("V_over_V0", "P", "aspect", "G_max", "G_mean", "G_min", "front_x", "front_y"),
            "uniform onset": ("V_over_V0", "P", "aspect", "G_max", "G_mean", "G_min")}
    return {name.replace(" ", "_"): {key: events[name][key] for key in keys[name]} if name in events else None
            for name in keys}
