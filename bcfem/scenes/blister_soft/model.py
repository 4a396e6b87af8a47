r"""The blister on a soft substrate as one energy: mesh, states, terms, conditions, observables.

In units of :math:`\mu_f t_0 R_0^2` (lengths by :math:`R_0`), with :math:`dA = 2\pi R\,dR`
on the substrate's top :math:`Z = 0` and :math:`dV = 2\pi R\,dR\,dZ` in it,

.. math:: \Pi = \underbrace{\int_{R<R_1} W_f(I_1^f)\,dA + \int_{R>R_1} W_f(I_1^s)\,dA}_{U_f}
          + \underbrace{\int k\,W_s(F, p)\,dV}_{U_s} - P\,V
          + \alpha \int_{R<R_1} \lambda_r^f\lambda_\theta^f\,dA
          + \gamma_{ls}\int_{R<R_1}\lambda_r^s\lambda_\theta^s\,dA
          + \int_{R>R_1}\Delta\gamma(R)\,\lambda_r^s\lambda_\theta^s\,dA,

:math:`k = \mu_s R_0/(\mu_f t_0)`, :math:`W_s` the nearly incompressible neo-Hookean law
with its mixed pressure, the free membrane :math:`x_f = x_s + w` (superscript f) and the
substrate's surface :math:`x_s` (superscript s, also the bonded membrane's position), and
the liquid volume :math:`V = -\int_0^1 \pi(r_f^2 z_f' - r_s^2 z_s')\,dR`
(:math:`R_1 = 1` for the bonded edge; the adhesive edge's front, :mod:`.front`).

A profile :math:`\Delta\gamma(R)` belongs to the substrate's material points (eq. 10.1's
:math:`\Delta\gamma(X)`, X on the undeformed top). With the front's map :math:`R = X(\xi; R_1)`
the bonded term is :math:`\int_{\xi>1}\Delta\gamma(X(\xi; R_1))\,a(\xi)\,d\xi`, a the
current area per :math:`d\xi` (fixed at fixed positions); in material variables that is
:math:`\int_{R_1}^{L}\Delta\gamma(R)\,\hat a(R)\,dR`, whose derivative at a fixed deformation
is :math:`-\Delta\gamma(R_1)\,\hat a(R_1)`. The two are one function of (deformation,
:math:`R_1`), so at equilibrium :math:`d\Pi/dR_1` sees :math:`\Delta\gamma(R_1)`. Evaluated at
the mesh's :math:`\xi` instead, the profile would travel with the front.

The states:
the substrate's displacement (P2) and pressure (P1), the lift w (P2 on the wetted facets,
0 at the contact vertex), and P (the arc-length load).

Natural conditions. Varying the lift at the contact vertex is excluded (w = 0 there), so
the membrane's material point R0 stays on the substrate's; varying the substrate's
displacement there collects every line force at the contact line,

.. math:: (N_r^- + \alpha)\,e_f + \gamma_{ls}\,e_{ls} + (N_r^+ + \Delta\gamma)\,e_s = 0,

with :math:`e_f, e_{ls}, e_s` the unit tangents leaving the contact line along the free
membrane, the wetted substrate and the bonded membrane, and :math:`N_r^\mp` the membrane's
meridian tractions on either side (the bulk carries no line force at finite energy). That is
eqs. 4.52-4.53; with :math:`N_r \to 0` (membrane-free limit) it is Neumann's triangle. The
scene only writes Π; the observables measure the three tangents (:class:`ContactLine`).
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import default_scalar_type, fem

from bcfem.geometry.substrate import AXIS, BOTTOM, FAR, OUTER_TOP, WETTED, create_mesh
from bcfem.kinematics.solid import AxisymmetricSolid
from bcfem.kinematics.submesh import BoundaryPatch
from bcfem.kinematics.surfaces import LiquidGap, MembraneSurface
from bcfem.mpi import PointEvaluator, cell_maximum, global_sum, real_value
from bcfem.path.branch import Switch
from bcfem.path.terminations import Reaches
from bcfem.physics.bcs import component
from bcfem.physics.composite import OnSurface, Scaled
from bcfem.physics.context import Context
from bcfem.physics.energies import MembraneStrain, PressureVolume, SolidStrain, SurfaceTension
from bcfem.physics.materials import Gent, NearlyIncompressibleNeoHookean, NeoHookean
from bcfem.physics.protocols import total_energy
from bcfem.radial_profile import RadialProfile, scale_of, shape_of
from bcfem.run.scene import BranchScene
from bcfem.scenes.blister_soft.front import front_weight, material_coordinates, weight_function
from bcfem.scenes.blister_soft.params import COLUMNS, Params
from bcfem.scenes.blister_soft.path import SoftScene
from bcfem.scenes.membrane_edges import moving_front
from bcfem.theory.membrane import droplet_angle_from_volume, simple_membrane_pressure

V0 = 4.0 * math.pi / 3.0  # 4/3 pi R0^3
LIFT = ("Lagrange", 2, (2,))


class Model:
    """The composed model: the mesh and its patch, the states, the surfaces and the terms."""

    def __init__(self, params: Params, comm, data=None, extra_terms=()):
        self.params = params
        g = params.geometry()
        self.geometry = g
        data = data or create_mesh(g, comm)
        msh, facets = data.mesh, data.facet_tags
        self.mesh, self.facets = msh, facets
        V = fem.functionspace(msh, ("Lagrange", 2, (2,)))
        self.u = fem.Function(V, name="displacement")
        self.ctx = Context(self.u)
        reference, self.rows, self.front = None, {}, None
        if params.edge == "adhesive":
            R1, self.front, self.rows, _ = moving_front(self.ctx)  # the front: 1 once released
            reference = material_coordinates(msh, R1, front_weight(msh, g.size_factor))
        solid = AxisymmetricSolid(self.u, quadrature_degree=4, facet_tags=facets, reference=reference)
        self.ctx.kin = solid
        self.patch = BoundaryPatch(msh, facets, WETTED)
        self.w = self.patch.state(self.ctx, "lift", LIFT)
        degree = 8  # the membranes' rational densities on P2 meridians
        L = g.size_factor
        self.free = MembraneSurface(solid, facets, WETTED, (0.0, 1.0), (self.w, self.patch.grad(self.w)[:, 0]),
                                    degree)
        self.wetted = MembraneSurface(solid, facets, WETTED, (0.0, 1.0), None, degree)
        self.bonded = MembraneSurface(solid, facets, OUTER_TOP, (1.0, L), None, degree)
        self.gap = LiquidGap(self.free, self.wetted)
        membrane = params_material(params)
        # in units of mu_s (its mixed pressure too), times k = mu_s R0/(mu_f t0), a constant
        substrate = NearlyIncompressibleNeoHookean(mu=1.0, kappa=params.kappa_ratio)
        self.terms = [Scaled(SolidStrain(substrate), "stiffness_ratio", params.stiffness_ratio),
                      OnSurface(MembraneStrain(membrane), self.free, "free"),
                      OnSurface(MembraneStrain(membrane), self.bonded, "bonded"),
                      OnSurface(PressureVolume(), self.gap, "liquid")]
        # a dgamma profile is a function of the material radius R = X(xi; R1) of the bonded top
        # (R > R1), not of the mesh's xi: at fixed positions dPi/dR1 then sees dgamma(R1)
        for gamma, name, surface in ((params.alpha, "gamma_l", self.free),
                                     (params.gamma_ls, "gamma_ls", self.wetted),
                                     (params.delta_gamma, "delta_gamma", self.bonded)):
            if scale_of(gamma) > 0:
                self.terms.append(OnSurface(SurfaceTension(scale_of(gamma), name, profile=shape_of(gamma)),
                                            surface, name))
        # the flat state's interface energies of the substrate, left out of the reported energy
        dgamma = params.delta_gamma
        self.energy_offset = params.gamma_ls + (dgamma.area_integral(1.0, L) if isinstance(dgamma, RadialProfile)
                                                else dgamma * (L**2 - 1))
        self.bcs = self._bcs(V, facets)
        self.terms.extend(extra_terms)
        for term in self.terms:  # create every state now (the pressures)
            term.energy(self.ctx)

    def _bcs(self, V, facets):
        """Bottom fixed, far side on rollers, axis u_r = 0; the lift is 0 at the contact
        vertex (the membrane's material point R0 is the substrate's) and w_r = 0 on the axis."""
        zero = np.zeros(2, dtype=default_scalar_type)
        bottom = fem.locate_dofs_topological(V, 1, facets.find(BOTTOM))
        W = self.w.function_space
        return [fem.dirichletbc(zero, bottom, V),
                component(V, 0, facets.find(FAR)), component(V, 0, facets.find(AXIS)),
                fem.dirichletbc(zero, self.patch.vertex_dofs(W, (1.0, 0.0)), W),
                fem.dirichletbc(0.0, self.patch.vertex_dofs(W.sub(0), (0.0, 0.0)), W.sub(0))]

    def form(self, expr):
        return fem.form(expr, entity_maps=self.ctx.entity_maps)

    def cap_guess(self, v_over_v0: float) -> float:
        """The substrate undeformed (x = X), the membrane a spherical cap of volume V/V0 on the
        base r = R1 (points spread uniformly along the arc); returns a pressure guess (simple
        membrane theory plus Laplace)."""
        for name, state in self.ctx.states.items():
            if name not in ("lift", "debond_radius"):
                state.x.array[:] = 0.0
        R1 = real_value(self.ctx.states["debond_radius"]) if self.front is not None else 1.0
        theta = droplet_angle_from_volume(v_over_v0 / R1**3)
        rho = R1 / math.sin(theta)
        psi = weight_function(self.geometry.size_factor)
        self.u.interpolate(lambda x: np.vstack([(R1 - 1) * psi(x), 0 * x[0]]))

        def lift(x):
            R = x[0] + (R1 - 1) * psi(x)  # the material radius on the top
            s = theta * R / R1
            return np.vstack([rho * np.sin(s) - R, rho * (np.cos(s) - math.cos(theta))])

        self.w.interpolate(lift)
        p = self.params
        pressure = min(float(simple_membrane_pressure(v_over_v0 / R1**3)), 2.0) / R1
        return pressure + 2.0 * p.alpha * math.sin(theta) / R1


def params_material(params: Params):
    return Gent(Jm=params.Jm) if params.material == "gent" else NeoHookean()


class ContactLine:
    """The unit tangents of the free membrane, the wetted substrate and the bonded surface at
    the contact vertex (R0, 0), leaving it, as the energy sees them (collective).

    Each is the line force a unit tension on that surface exerts on the vertex, -dA/dx at the
    vertex's displacement dofs: the tangent of the adjacent element weighted as the P2 shape
    function of the vertex weights it. At a ridge whose flank turns within the last element
    the one-sided nodal slope is a mesh-scale quantity; these directions are the ones whose
    tensions the discrete balance (:func:`contact_forces`) holds."""

    def __init__(self, model: Model):
        u = model.u
        V = u.function_space
        v = ufl.TestFunction(V)
        self.forms = [model.form(ufl.derivative(s.integral(s.area_stretch), u, v))
                      for s in (model.free, model.wetted, model.bonded)]
        self.vertex = _owned_vertex_dofs(V)
        self.at = PointEvaluator(model.mesh, [1.0, 0.0]).expression(u)
        self.comm = model.mesh.comm

    def __call__(self) -> dict:
        e_f, e_ls, e_s = (_unit(-_vertex_load(form, self.vertex, self.comm)) for form in self.forms)
        return {"e_f": e_f, "e_ls": e_ls, "e_s": e_s, "r0": 1.0 + float(self.at()[0])}


def _unit(vector: np.ndarray) -> np.ndarray:
    return vector / np.linalg.norm(vector)


def _owned_vertex_dofs(V) -> np.ndarray:
    """The contact vertex's displacement dofs owned by this rank (blocks of V)."""
    dofs = fem.locate_dofs_geometrical(V, lambda x: np.isclose(x[0], 1.0) & np.isclose(x[1], 0.0))
    return dofs[dofs < V.dofmap.index_map.size_local]


def _vertex_load(form, vertex, comm) -> np.ndarray:
    """The (r, z) entries of an assembled vector form at the contact vertex, on every rank."""
    from dolfinx import la

    vec = fem.assemble_vector(form)
    vec.scatter_reverse(la.InsertMode.add)
    local = vec.array.reshape(-1, 2)[vertex].sum(axis=0) if vertex.size else np.zeros(2)
    return comm.allreduce(local)


def angle(a, b) -> float:
    """The angle between two vectors, in degrees."""
    return math.degrees(math.acos(np.clip(np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b)), -1, 1)))


def observables(model: Model):
    """Compile the observables once; returns a collective callable."""
    ctx, u, w = model.ctx, model.u, model.w
    volume = model.form(model.gap.integral(model.gap.volume_density))
    # where a principal tension of the free membrane is negative: N_i has the sign of
    # lambda_i^2 - 1/(lambda_r lambda_theta)^2 for neo-Hookean and Gent (a membrane without
    # bending stiffness would wrinkle there)
    f = model.free
    compressed = ufl.conditional(ufl.Or(ufl.lt(f.lam_theta**2 * f.lam_r, 1), ufl.lt(f.lam_r**2 * f.lam_theta, 1)), 1, 0)
    compressed = model.form(f.integral(compressed))
    energy = model.form(total_energy(ctx, model.terms))
    centre = PointEvaluator(model.mesh, [0.0, 0.0]).expression(u[1])
    W = w.function_space
    axis = model.patch.vertex_dofs(W, (0.0, 0.0))
    owned_axis = axis[axis < W.dofmap.index_map.size_local]
    pressure = ctx.real_state("pressure")
    line = ContactLine(model)
    comm = model.mesh.comm
    inversion = cell_maximum(model.mesh, -ctx.kin.J, 2)  # at the solid's Gauss points
    front = None
    if "debond_radius" in ctx.states:
        R1 = ctx.states["debond_radius"]
        one = fem.Function(R1.function_space)
        one.x.array[:] = 1.0
        # the configurational force on the front, d Pi/d R1 at fixed positions (the J-integral)
        front = model.form(ufl.derivative(total_energy(ctx, model.terms), R1, one))

    def observe() -> dict:
        lift_apex = comm.allreduce(float(w.x.array.reshape(-1, 2)[owned_axis, 1].sum()))
        z_s = float(centre()[0])
        here = line()
        e_f, e_ls, e_s = here["e_f"], here["e_ls"], here["e_s"]
        debond_radius = real_value(ctx.states["debond_radius"]) if front else 1.0
        return {
            "V_over_V0": global_sum(volume) / V0,
            "P": real_value(pressure),
            "aspect": (z_s + lift_apex) / here["r0"],
            # the membrane against the substrate's undeformed plane (the rigid scene's angle): the
            # substrate's own tangents at the vertex carry the mesh-scale tent of any line force
            # the bulk takes (slope ~ F/(mu_s h)), see docs/results.md
            "contact_angle_deg": 180.0 - angle(e_f, np.array([1.0, 0.0])),
            "indentation": -z_s,
            "r1_over_R0": here["r0"],
            "R1_over_R0": debond_radius,
            **({"dPi_dR1": global_sum(front) / math.pi} if front else {}),
            "energy": global_sum(energy) / math.pi - model.energy_offset,
            "z_apex": z_s + lift_apex,
            # the three angles at the contact line: in the liquid, in the substrate, between
            # the membrane's two parts (they sum to 360 degrees)
            "liquid_angle_deg": angle(e_f, e_ls),
            "substrate_angle_deg": angle(e_ls, e_s),
            "membrane_angle_deg": angle(e_f, e_s),
            "J_min": -inversion(),
            "compressed_fraction": global_sum(compressed) / (math.pi * debond_radius**2),
            "_line": here,
        }

    return observe


def build(params: Params, comm, data=None, extra_terms=()) -> BranchScene:
    """Compose the blister on a soft substrate (``data``: a distributed substrate mesh to reuse;
    ``extra_terms``: a research script's terms, added to its energy)."""
    model = Model(params, comm, data, extra_terms)
    observe_all = observables(model)

    def observe():
        return {k: v for k, v in observe_all().items() if not k.startswith("_")}

    def guard(values):
        if values["V_over_V0"] <= 0:
            return f"the blister volume is not positive (V/V0 = {values['V_over_V0']:.3g})"
        if not values["J_min"] > 0:
            return (f"the substrate inverts (min J = {values['J_min']:.3g} at V/V0 = {values['V_over_V0']:.4g}): the "
                    f"line force at the contact line, which the interface tensions leave to the bulk, is too large "
                    f"for its modulus; the state is not physical (see docs/results.md, chapter 4)")
        if values["R1_over_R0"] > params.size_factor / 2:
            return (f"the debond radius R1/R0 = {values['R1_over_R0']:.4g} passed half the block "
                    f"(size-factor {params.size_factor:g}); raise --size-factor or lower --v-max")
        return None

    switches = []
    if model.front is not None:
        # Griffith, no healing: the front moves once the release rate -dPi/dR1 turns positive
        switches.append(Switch("delamination onset", lambda values: -values["dPi_dR1"],
                               lambda: setattr(model.front, "value", 1.0), grows="debond_radius"))

    scene = SoftScene(
        name="blister-soft", ctx=model.ctx, terms=model.terms, bcs=model.bcs, load="pressure",
        start=lambda fraction: model.cap_guess(fraction * params.v_start), observe=observe,
        end=Reaches("V_over_V0", params.v_max), grows="V_over_V0",
        progress_keys=("V_over_V0", "P", "indentation"), fields=[model.u, model.w],
        continuation=params.continuation,
        plots={"pv.png": ("V_over_V0", "P", "V/V0", "P = Δp R0/(μf t0)"),
               "indentation.png": ("V_over_V0", "indentation", "V/V0", "-z_s(0)/R0")},
        load_scale=max(1.0, 2 * params.alpha), guard=guard, params=params,
        summarize=lambda branch: summarize(branch, scene.start_report),
        columns=COLUMNS, rows=model.rows, switches=switches,
        # the residual's round-off floor: a stiff substrate's stress k(F - F^-T) at F ~ I loses
        # k eps; in the unit k/1000 (path.energy_scale) that is ~1e-10 from k = 1e3 on, where
        # Newton stalled on converged states at k = 1e5 and 1e6 with bcfem's 1e-10
        petsc_options={"snes_atol": 1e-9})
    scene.norm = {"displacement": 1.0, "lift": 1.0}
    scene.mean = model.free.mean
    scene.model = model
    return scene


def summarize(branch, start_report=None) -> dict:
    """``indentation_max``: the deepest indentation along the branch (a parabola through the
    three rows around the deepest one), and where it is; ``branch_start``: None, or where the
    branch begins when no regular state reaches down to ``v_start`` (:meth:`.path.SoftScene.trace_back`)."""
    depth = branch.column("indentation")
    volume = branch.column("V_over_V0")
    k = int(np.argmax(depth))
    result = {"V_over_V0": float(volume[k]), "depth": float(depth[k]), "interior": False}
    if 0 < k < len(depth) - 1:
        c = np.polyfit(volume[k - 1:k + 2], depth[k - 1:k + 2], 2)
        if c[0] < 0:
            v = -c[1] / (2 * c[0])
            result = {"V_over_V0": float(v), "depth": float(np.polyval(c, v)), "interior": True}
    onset = next((e for e in branch.events if e["name"] == "delamination onset"), None)
    return {"indentation_max": result, "branch_start": start_report,
            "delamination_onset": None if onset is None else {
                key: onset[key] for key in ("V_over_V0", "P", "r1_over_R0", "energy", "dPi_dR1")}}


def contact_forces(model: Model) -> dict:
    """The line force (per current length of the contact line) that each term exerts on the
    substrate's contact vertex: minus the term's residual at the vertex's two displacement
    dofs over 2 pi r0. At equilibrium they sum to zero; the contact-line conditions are
    natural when the bulk's share (``stiffness_ratio*solid_strain``) vanishes as the mesh is
    refined, the membranes' and interfaces' forces then balancing alone (collective)."""
    V = model.u.function_space
    vertex = _owned_vertex_dofs(V)
    comm = model.mesh.comm
    r0 = 1.0 + float(PointEvaluator(model.mesh, [1.0, 0.0]).expression(model.u)()[0])
    v = ufl.TestFunction(V)
    return {term.name: -_vertex_load(model.form(ufl.derivative(term.energy(model.ctx), model.u, v)), vertex, comm)
            / (2 * math.pi * r0) for term in model.terms}
