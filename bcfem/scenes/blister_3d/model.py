"""The three-dimensional blister: a membrane on its flat reference outline, clamped along
it, inflated at a pressure traced by arc-length (the terms of ``blister-rigid`` on
:class:`bcfem.kinematics.planar_membrane.PlanarMembrane` kinematics)."""

from __future__ import annotations

import math

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem

from bcfem.geometry.outline import EDGE, create_mesh
from bcfem.kinematics.planar_membrane import PlanarMembrane
from bcfem.mpi import cell_maximum, global_sum, real_value
from bcfem.physics.context import Context
from bcfem.physics.energies import MembraneStrain, PressureVolume, SurfaceTension
from bcfem.scenes.blister_3d.params import COLUMNS, V0, Params
from bcfem.scenes.blister_3d.report import MembraneScene
from bcfem.scenes.blister_3d.start import FopplStart


def build(params: Params, comm, extra_terms=()) -> MembraneScene:
    """The blister of ``params`` (see :mod:`bcfem.scenes.blister_3d.params`)."""
    data = create_mesh(params.geometry(), comm)
    msh = data.mesh
    V = fem.functionspace(msh, ("Lagrange", params.degree, (3,)))
    u = fem.Function(V, name="displacement")
    ctx = Context(u)
    ctx.kin = PlanarMembrane(u, quadrature_degree=2 * params.degree + 2, relaxed=params.wrinkles == "relaxed")
    edge_facets = data.facet_tags.find(EDGE)
    fdim = msh.topology.dim - 1
    bcs = [fem.dirichletbc(np.zeros(3), fem.locate_dofs_topological(V, fdim, edge_facets), V)]
    terms = [MembraneStrain(params.material_model())]
    if params.alpha > 0:
        terms.append(SurfaceTension(params.alpha))
    terms.append(PressureVolume())
    terms.extend(extra_terms)

    guess = FopplStart(V, edge_facets)

    def start(fraction: float = 1.0) -> float:
        """u: the Föppl membrane's shape at V/V0 = fraction v-start; returns its pressure."""
        return guess.apply(u, fraction * params.v_start * V0, tension=params.alpha)

    kin = ctx.kin
    volume = fem.form(kin.integral(kin.volume_density))
    energy = fem.form(sum(t.energy(ctx) for t in terms))
    pressure = ctx.real_state("pressure")
    degree = params.degree
    I1 = cell_maximum(msh, kin.I1 - 3, degree)
    stretch = cell_maximum(msh, kin.principal_stretches()[0], degree)
    heights = V.sub(2).collapse()[1]  # the z components in u.x.array
    I1_taut = ufl.variable(kin.taut_I1)
    dW = ufl.diff(params.material_model().strain_energy(I1_taut), I1_taut)
    N2 = kin.principal_tensions(dW)[1] + params.alpha
    compression = cell_maximum(msh, -N2, degree)
    wrinkled = fem.form(kin.integral(ufl.conditional(ufl.lt(N2, 0), 1.0, 0.0) / kin.reference_area))
    measures = fem.Function(V, name="measures")
    direction = fem.Function(V, name="tension_direction")
    drawn = [(f, fem.Expression(e, V.element.interpolation_points))
             for f, e in ((measures, ufl.as_vector([*kin.principal_stretches(), N2])),
                          (direction, kin.tension_direction()))]

    def observe() -> dict:
        for f, expression in drawn:
            f.interpolate(expression)
        apex = msh.comm.allreduce(float(u.x.array[heights].max(initial=-np.inf)), op=MPI.MAX)
        return {"V_over_V0": global_sum(volume) / V0, "P": real_value(pressure), "aspect": apex,
                "energy": global_sum(energy) / math.pi, "stretch_max": stretch(), "I1_minus_3_max": I1(),
                "N2_min": -compression(), "wrinkled_fraction": global_sum(wrinkled)}

    def guard(values):
        if values["V_over_V0"] <= 0:
            return (f"the blister volume is not positive (V/V0 = {values['V_over_V0']:.3g}, "
                    f"P = {values['P']:.6g}): the membrane would pass through the substrate")
        if params.material == "gent" and values["I1_minus_3_max"] > 0.99 * params.Jm:
            return (f"the Gent membrane is locking: max(I1 - 3) = {values['I1_minus_3_max']:.6g} reached "
                    f"0.99 Jm (Jm = {params.Jm:g}) at V/V0 = {values['V_over_V0']:.6g}; lower --v-max or raise --Jm")
        return None

    return MembraneScene(name="blister-3d", ctx=ctx, terms=terms, bcs=bcs, load="pressure", start=start,
                 observe=observe, end=lambda values: values["V_over_V0"] - params.v_max, grows="V_over_V0",
                 progress_keys=("V_over_V0", "P", "aspect"), fields=[u, measures, direction],
                 continuation=params.continuation,
                 plots={"pv.png": ("V_over_V0", "P", "V/V0", "P = Δp R0/(μ t0)")},
                 load_scale=max(1.0, 2 * params.alpha), guard=guard, params=params, columns=COLUMNS)

