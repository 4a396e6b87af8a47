r"""Non-axisymmetric loss of stability of an axisymmetric state: Fourier modes.

An axisymmetric model sees only axisymmetric modes. At an axisymmetric state a
perturbation with n circumferential waves,

.. math:: \delta u = a\cos n\theta\, e_r + c\cos n\theta\, e_z + b\sin n\theta\, e_\theta,
          \qquad \delta p = q \cos n\theta,

is decoupled from every other n (and the sine/cosine twins from each other, by
the reflection θ → -θ), so the second variation of the energy integrated over θ
is a 2-D quadratic form in (a, c, b, q): the n-th block of the 3-D tangent. Its
deformation gradient, components ordered (r, z, θ) as in
:class:`bcfem.kinematics.solid.AxisymmetricSolid`, is F0 + G with

.. math:: G = \begin{pmatrix} a_{,r} & a_{,z} & -(na + b)/r \\
                              c_{,r} & c_{,z} & -nc/r \\
                              b_{,r} & b_{,z} & (nb + a)/r \end{pmatrix}
          (\cos n\theta \text{ and } \sin n\theta \text{ factors dropped}).

:class:`ModeKinematics` is kinematics like the axisymmetric one (F, J, I1, the
cavity's height and Nanson vector, the θ-integral π instead of 2π), so the
scene's own energy terms give the block by differentiating twice: nothing is
derived by hand. Global unknowns (a gas pressure, a sealed volume) do not
couple to n >= 1: their first variation integrates to zero over θ, so they
stay at their values. Dirichlet conditions of the axisymmetric state hold the
same components of the mode; the axis is regular when c = 0 there and, for
n >= 2, a = b = 0. For n = 1 the axis may move sideways, a = -b: the unknowns
are then (a, c, a + b) (a congruence: the inertia is the same) so that this is
a Dirichlet condition, and a rigid sideways translation, which costs nothing,
has its mean over the body held by a multiplier.

Unstable directions are counted as in :mod:`bcfem.stability.inertia` (Sylvester's law
on the saddle-point matrix). Discrete terms (self-contact) are not included.

G is linear in the mode and affine in n, and the block is the second variation
at the mode's zero, D²L[G(δw), G(Δw)] (no second derivative of G): so the
block is exactly quadratic in n. A scan of many n >= 2 assembles it at three
wave numbers and interpolates the others (three sums of matrices each), which
is the same matrix up to round-off.
"""

from __future__ import annotations

import math

from petsc4py import PETSc

import numpy as np
import ufl
from dolfinx import default_scalar_type, fem
from dolfinx.fem.petsc import assemble_matrix, create_matrix

from bcfem.mpi import global_dofs
from bcfem.physics.protocols import DiscreteTerm, total_energy
from bcfem.stability.inertia import Inertia


class ModeKinematics:
    """The axisymmetric kinematics ``base`` perturbed by the mode field ``w`` with ``n`` waves
    (a ``fem.Constant``): w = (a, c, b), or w = (a, c, a + b) with ``sideways`` (n = 1), whose
    axis condition a + b = 0 is then a condition on one component."""

    def __init__(self, base, w, n, sideways: bool = False):
        self.base = base
        self.x = base.x
        r = base.x[0]
        a, c, b = w[0], w[1], (w[2] - w[0] if sideways else w[2])
        self.sideways_displacement = a - b  # twice the mean of e_x . (a cos e_r + b sin e_theta)
        G = ufl.as_matrix([[a.dx(0), a.dx(1), -(n * a + b) / r],
                           [c.dx(0), c.dx(1), -n * c / r],
                           [b.dx(0), b.dx(1), (n * b + a) / r]])
        self.F = base.F + G
        self.J = ufl.det(self.F)
        self.I1 = ufl.tr(self.F.T * self.F)
        self.height = base.height + c
        self.normal = base.normal
        self.surface_stretch = ufl.sqrt(ufl.inner(self.nanson(), self.nanson()))

    def nanson(self):
        """cof(F) N, components (r, z, theta)."""
        N = ufl.as_vector([self.normal[0], self.normal[1], 0])
        return ufl.dot(ufl.cofac(self.F), N)

    def vertical_area(self):
        """The z component of :meth:`nanson`."""
        return self.nanson()[1]

    # the theta-integral of cos^2(n theta) or sin^2(n theta) is pi, half the axisymmetric 2 pi
    def integral(self, density, region: int | None = None):
        return 0.5 * self.base.integral(density, region)

    def surface_integral(self, density, boundary: int):
        return 0.5 * self.base.surface_integral(density, boundary)


class ModeContext:
    """What energy terms see when they build the mode's Lagrangian: the mode kinematics,
    field states perturbed (base + mode), global states and constants as they are."""

    def __init__(self, ctx, n, sideways: bool = False):
        self.base = ctx
        self.mesh = ctx.mesh
        space = ctx.u.function_space
        degree = space.element.basix_element.degree
        self.space = fem.functionspace(self.mesh, ("Lagrange", degree, (3,)))
        self.w = fem.Function(self.space, name="mode")
        self.kin = ModeKinematics(ctx.kin, self.w, n, sideways)
        self._states = {"mode": self.w}

    def field_state(self, name: str, degree: int = 1):
        base = self.base.field_state(name, degree)
        if name not in self._states:
            self._states[name] = fem.Function(base.function_space, name=f"{name}_mode")
        return base + self._states[name]

    def real_state(self, name: str):
        return self.base.real_state(name)

    def multiplier(self, name: str):
        """A global unknown of the mode's own (e.g. the n = 1 translation's multiplier)."""
        if name not in self._states:
            self._states[name] = fem.Function(self.base.real_space, name=name)
        return self._states[name]

    def constant(self, name: str, value: float = 0.0):
        return self.base.constant(name, value)

    def parameters(self, owner, names=None):
        return self.base.parameters(owner, names)

    def body_measure(self):
        return self.base.body_measure()

    @property
    def u(self):
        raise AttributeError("this term needs the displacement itself, which a Fourier mode does not "
                             "define; leave it out of the terms of bcfem.stability.modes.ModeAnalysis")

    @property
    def states(self):
        return dict(self._states)


class ModeAnalysis:
    """Counts the unstable Fourier modes n >= 1 of the current axisymmetric state of ``ctx``.

    Its matrices and factorisations are kept from count to count; :meth:`close` destroys
    them (collective).

    Args:
        ctx: the axisymmetric model's context (its states are the base state).
        terms: the energy terms of the current stage (discrete terms and terms that need
            the displacement itself, such as a relaxation viscosity, must be left out).
        bcs: the axisymmetric problem's Dirichlet conditions on the displacement.
        prefix: PETSc options prefix of the factorisations.
    """

    #: a scan interpolates the block in n when it has at least this many n >= 2
    INTERPOLATE_FROM = 4

    def __init__(self, ctx, terms, bcs, prefix: str = "bcfem_modes_"):
        self.ctx = ctx
        self.terms = [t for t in terms if not isinstance(t, DiscreteTerm)]
        self.prefix = prefix
        self.n = fem.Constant(ctx.mesh, default_scalar_type(2.0))
        self._forms: dict[str, dict] = {}  # n = 1 (with the translation multiplier) and n >= 2
        base_space = ctx.u.function_space
        self._base_bs = base_space.dofmap.index_map_bs
        self._held = [bc.dof_indices()[0] for bc in bcs]

    def _build(self, translation: bool):
        mctx = ModeContext(self.ctx, self.n, sideways=translation)
        V = mctx.space
        if not np.allclose(V.tabulate_dof_coordinates(), self.ctx.u.function_space.tabulate_dof_coordinates()):
            raise RuntimeError("the mode's dofs do not follow the displacement's node numbering")
        lagrangian = total_energy(mctx, self.terms)
        if translation:
            shift = mctx.multiplier("translation")
            # mean sideways displacement e_x . (a cos e_r + b sin e_theta) over the body
            lagrangian += mctx.kin.integral(shift * mctx.kin.sideways_displacement)
        states = list(mctx.states.values())
        # the multipliers of the mode: the perturbations of the field multipliers the terms
        # declare (a mixed pressure) and the translation's; global ones do not couple to n >= 1
        declared = {n for t in self.terms for n in t.multipliers} | {"translation"}
        multipliers = global_dofs(s for n, s in mctx.states.items() if n in declared)
        blocks = []
        for si in states:
            row = []
            for sj in states:
                block = ufl.derivative(ufl.derivative(lagrangian, si, ufl.TestFunction(si.function_space)),
                                       sj, ufl.TrialFunction(sj.function_space))
                block = ufl.algorithms.expand_derivatives(block)
                row.append(None if block.empty() else block)
            blocks.append(row)
        forms = fem.form(blocks)  # type: ignore[arg-type]  # dolfinx takes None for an empty block
        return {"forms": forms, "space": V, "multipliers": multipliers,
                "nodes": V.tabulate_dof_coordinates(), "matrix": create_matrix(forms), "nodal": [],
                "inertia": Inertia(self.prefix)}

    def _compiled(self, n: int) -> dict:
        kind = "translation" if n == 1 else "waves"
        if kind not in self._forms:
            self._forms[kind] = self._build(translation=(n == 1))
        return self._forms[kind]

    def _bcs(self, compiled, n: int, held) -> list:
        V = compiled["space"]
        bs = self._base_bs
        on_axis = np.flatnonzero(np.isclose(compiled["nodes"][:, 0], 0.0, atol=1e-12))
        fixed: dict[int, list] = {k: [] for k in range(3)}
        for dofs in [*self._held, *([np.asarray(held)] if held is not None else [])]:
            nodes, comps = np.divmod(np.asarray(dofs, dtype=np.int64), bs)
            for k in range(bs):
                chosen = nodes[comps == k]
                if n == 1 and k == 0:  # the axis may move sideways (a = -b there)
                    chosen = np.setdiff1d(chosen, on_axis)
                fixed[k].append(chosen)
        fixed[1].append(on_axis)  # c = 0
        fixed[2].append(on_axis)  # b = 0, or a + b = 0 for n = 1
        if n >= 2:
            fixed[0].append(on_axis)
        return [fem.dirichletbc(0.0, (3 * np.unique(np.concatenate(nodes)) + k).astype(np.int32),
                                V.sub(k)) for k, nodes in fixed.items() if nodes]

    def _assemble(self, compiled, n: int, bcs, A: PETSc.Mat) -> PETSc.Mat:
        self.n.value = np.asarray(float(n))
        A.zeroEntries()
        assemble_matrix(A, compiled["forms"], bcs=bcs)  # type: ignore[misc]  # the Mat overload of a singledispatch
        A.assemble()
        return A

    def _count(self, compiled, A: PETSc.Mat) -> int:
        return compiled["inertia"].negative(A) - compiled["multipliers"]

    def unstable(self, n: int, held=None) -> int:
        """Number of unstable modes with ``n`` >= 1 waves at the current state.

        Args:
            held: local (unrolled) dofs of the displacement held at this state in addition
                to the Dirichlet conditions, e.g. wall dofs in contact with a rigid plate
                (frictionless: only their normal component).
        """
        if n < 1 or int(n) != n:
            raise ValueError(f"the wave number n must be an integer >= 1 (got {n})")
        compiled = self._compiled(int(n))
        A = self._assemble(compiled, int(n), self._bcs(compiled, int(n), held), compiled["matrix"])
        return self._count(compiled, A)

    def scan(self, waves, held=None) -> dict[int, int]:
        """{n: unstable modes} for every n in ``waves``."""
        if any(n < 1 or int(n) != n for n in waves):
            raise ValueError(f"the wave numbers must be integers >= 1 (got {list(waves)})")
        waves = sorted({int(n) for n in waves})
        many = [n for n in waves if n >= 2]
        if len(many) < self.INTERPOLATE_FROM:
            return {n: self.unstable(n, held) for n in waves}
        counts = {1: self.unstable(1, held)} if 1 in waves else {}
        compiled = self._compiled(2)
        for n, A in zip(many, self.interpolated(many, held)):
            counts[n] = self._count(compiled, A)
        return counts

    def interpolated(self, waves, held=None):
        """The blocks of the wave numbers ``waves`` (all >= 2, at least three), each
        interpolated from the blocks assembled at the least, the middle and the greatest of
        them (Lagrange, exact for a quadratic); each is yielded in the same kept matrix."""
        compiled = self._compiled(2)
        nodes = sorted({min(waves), waves[len(waves) // 2], max(waves)})
        if len(nodes) < 3:
            raise ValueError(f"interpolation needs three distinct wave numbers (got {waves})")
        nodal = compiled["nodal"]
        while len(nodal) < 3:
            nodal.append(create_matrix(compiled["forms"]))
        bcs = self._bcs(compiled, 2, held)
        for node, B in zip(nodes, nodal):
            self._assemble(compiled, node, bcs, B)
        A = compiled["matrix"]
        if not A.assembled:  # the forms' pattern, which the sums keep
            self._assemble(compiled, nodes[0], bcs, A)
        same = PETSc.Mat.Structure.SAME_NONZERO_PATTERN
        for n in waves:
            weights = [math.prod((n - m) / (node - m) for m in nodes if m != node) for node in nodes]
            A.zeroEntries()
            for weight, B in zip(weights, nodal):
                A.axpy(weight, B, same)
            yield A

    def close(self) -> None:
        """Destroy the kept matrices and factorisations (collective)."""
        for compiled in self._forms.values():
            compiled["inertia"].close()
            for A in [compiled["matrix"], *compiled["nodal"]]:
                A.destroy()
        self._forms = {}
