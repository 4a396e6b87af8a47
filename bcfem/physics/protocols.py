r"""The contracts between terms, kinematics and the problem builder, as typed protocols.

A model is a list of terms. Most are :class:`Term` s: a scalar UFL energy that
:class:`bcfem.solver.problem.Problem` sums and differentiates. A few effects are not
one form (self-contact couples boundary nodes far apart in the mesh): they are
:class:`DiscreteTerm` s, which add their residual and tangent to the assembled
system. A :class:`Term` is structural (``typing.Protocol``): it conforms by having
the members. A discrete term inherits from :class:`DiscreteTerm`, whose hooks default
to doing nothing.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Protocol, TypeVar, runtime_checkable

if TYPE_CHECKING:
    from mpi4py import MPI
    from petsc4py import PETSc

    import ufl
    from dolfinx import fem

    from bcfem.physics.context import Context


@runtime_checkable
class Kinematics(Protocol):
    """What every kinematics offers the terms: the one integral over the reference body (the
    only place an axisymmetric weight 2πR is applied), and its mean.

    The dimension-specific layer: a term reads only these members, so it acts unchanged on
    every kinematics that offers them.

    * membranes (:class:`bcfem.kinematics.membrane.AxisymmetricMembrane`,
      :class:`bcfem.kinematics.planar_membrane.PlanarMembrane`): ``I1``, ``area_stretch``,
      ``volume_density``, ``projected_area_density``, ``reference_area``;
    * solids (:class:`bcfem.kinematics.solid.AxisymmetricSolid`, :class:`bcfem.kinematics.solid_3d.Solid3D`):
      ``F``, ``J``, ``I1``, ``height``, ``surface_integral``, ``surface_stretch``,
      ``nanson()``, ``vertical_area()``, ``reference_volume``.

    ``tests/test_kinematics_shared.py`` checks that one set of solid terms gives the same
    energies on an axisymmetric body and on 3-D quarters of it."""

    def integral(self, density, region: int | None = None) -> ufl.Form:
        """``density`` (per unit reference area or volume) integrated over the
        reference body, or over the cells tagged ``region``."""
        ...

    def mean(self, density) -> ufl.Form:
        """The reference mean of ``density`` (the arc-length inner product)."""
        ...


@runtime_checkable
class ProblemView(Protocol):
    """What a discrete term may ask of the problem it is bound to
    (:class:`bcfem.solver.problem.Problem` offers these)."""

    ctx: Context

    @property
    def comm(self) -> MPI.Comm:
        """The problem's communicator."""
        ...

    #: the scale a term's residual and tangent are multiplied by, as the forms are
    inverse_scale: fem.Constant

    def global_indices(self, name: str):
        """The global rows of state ``name``'s local dofs (unrolled blocks)."""
        ...

    def constrained(self, name: str):
        """Whether each local dof of ``name`` is held by a Dirichlet condition."""
        ...

    def allow_new_nonzeros(self) -> None:
        """Let the term add entries outside the forms' sparsity."""
        ...


class Term:
    r"""A physical effect as an energy: the problem's residual and tangent are its
    derivatives (never written by hand). Every energy term inherits this base, usually
    as a frozen dataclass, and overrides :meth:`energy`; the problem refuses an object
    that is neither a :class:`Term` nor a :class:`DiscreteTerm`.

    Attributes:
        name: identifies the term in messages and look-ups. A term with a run-time
            constant is named after it, so that two terms of one class (a wetted blister
            and a wetted film) are told apart. Default: the class's name.
        multipliers: names of the states the term creates that are Lagrange multipliers
            (default none): unknowns whose row is a constraint or an equation of state,
            such as a mixed solid pressure or a sealed fluid's pressure. Each multiplier
            dof adds one negative eigenvalue to the Hessian of the Lagrangian whatever the
            stability of the body, so :func:`bcfem.stability.inertia.unstable_modes`
            subtracts them (Sylvester's law). A state that is a real unknown of the energy
            (a debond radius) is none, and a problem that replaces a multiplier's row (an
            arc-length load) no longer counts it (``Problem.multipliers``).
        stages: the stages of a scene whose energy the term belongs to, when a research
            script adds it to a scene (``build(..., extra_terms=[...])``); default None: every
            stage.
    """

    @property
    def name(self) -> str:
        return type(self).__name__

    @property
    def multipliers(self) -> tuple[str, ...]:
        return ()

    @property
    def stages(self) -> tuple[str, ...] | None:
        return None

    def belongs_to(self, stage: str) -> bool:
        """Whether the term is part of the energy of the scene's stage ``stage``."""
        return self.stages is None or stage in self.stages

    def inadmissible(self, ctx: Context) -> str | None:
        """Why the converged state of ``ctx`` is unphysical for this term (an inverted
        element: the problem then rejects it, and the solve fails like any other), or None.
        Collective. Default: every state is admissible."""
        return None

    def energy(self, ctx: Context) -> ufl.Form:
        """The term's energy as one scalar UFL form in the reference configuration.

        Touches only ``ctx``: its kinematics ``ctx.kin``, its states (created on
        first request with ``ctx.real_state`` or ``ctx.field_state``) and its run-time
        constants (``ctx.constant``, so that the form compiles once). May be called
        more than once, also with another context (a Fourier mode's,
        :mod:`bcfem.stability.modes`).
        """
        raise NotImplementedError(f"{type(self).__name__} defines no energy")


class DiscreteTerm:
    """An effect that is not one UFL form: it adds its residual and tangent to the
    system the problem assembles from the forms. Discrete terms inherit from this base,
    which the problem recognises (``isinstance``) and whose hooks default to doing nothing:
    a subclass implements :meth:`bind`, :meth:`add_residual` and :meth:`add_jacobian`, and
    overrides a hook only where it needs one."""

    #: the term adds no energy form
    is_discrete = True
    #: True when :meth:`add_jacobian` adds a symmetric matrix (the Hessian of an energy), so
    #: that the problem may factorise its tangent as LDL^T
    symmetric_tangent = False
    multipliers: tuple[str, ...] = ()

    def bind(self, problem: ProblemView) -> None:
        """Set up once, when ``problem`` is built (after its forms): find the term's
        unknowns (``problem.global_indices``, ``problem.constrained``), keep
        ``problem.inverse_scale`` to scale like the forms, and call
        ``problem.allow_new_nonzeros()`` if it adds entries outside their sparsity."""
        raise NotImplementedError

    def add_residual(self, b: PETSc.Vec) -> None:
        """Add the term's residual (scaled by ``problem.inverse_scale``) to the
        assembled residual ``b``, at the states the problem's functions hold. Rows
        of Dirichlet dofs hold their own equation and get nothing. Collective."""
        raise NotImplementedError

    def add_jacobian(self, A: PETSc.Mat) -> None:
        """Add the derivative of :meth:`add_residual` to the assembled tangent ``A``
        (free rows and columns only), and assemble ``A``. Collective."""
        raise NotImplementedError

    def tangent_key(self) -> tuple | None:
        """Arrays that, with the states, determine what :meth:`add_jacobian` adds (e.g. a
        choice frozen per solve), so that a tangent assembled at the same states and keys is
        not assembled again (:mod:`bcfem.solver.tangent_memo`). Default: None, assembled every time."""
        return None

    def begin_solve(self) -> None:
        """Called before each Newton solve, e.g. to freeze a choice that must not
        change between iterates. Default: nothing."""
        return None

    def inadmissible(self) -> str | None:
        """Why the converged state is unphysical (the solve then fails like any
        other), or None. Default: None, every state is admissible."""
        return None

    def step_bound(self, x: PETSc.Vec, y: PETSc.Vec) -> float:
        """The largest fraction t <= 1 of Newton's update x - y (states x, step y)
        that keeps the state admissible; used once ``problem.bound_steps()`` is
        called. Default: 1, no bound."""
        return 1.0

    @classmethod
    def bounds_steps(cls) -> bool:
        """Whether the class overrides :meth:`step_bound` (the problem then asks it)."""
        return cls.step_bound is not DiscreteTerm.step_bound


T = TypeVar("T")


def find_term[T](terms: Iterable, kind: type[T]) -> T:
    """The one term of class ``kind`` (or a subclass) in ``terms``.

    Observables use this instead of a position in the list, which reordering
    would silently change.

    Raises:
        LookupError: when there is none, or more than one.
    """
    terms = list(terms)
    found = [t for t in terms if isinstance(t, kind)]
    if len(found) != 1:
        names = ", ".join(type(t).__name__ for t in terms) or "none"
        raise LookupError(f"expected exactly one {kind.__name__} among the terms, found {len(found)} "
                          f"(terms: {names})")
    return found[0]


class Hyperelastic(Protocol):
    """A strain energy per unit reference volume as a function of the invariants I1 and I2
    (:mod:`bcfem.physics.materials`; most ignore I2)."""

    def strain_energy(self, I1, I2=None): ...


class SolidMaterial(Protocol):
    """A solid's energy density at a displacement and a mixed pressure (a nearly incompressible solid)."""

    def density(self, kin, pressure): ...


class Shape(Protocol):
    """A dimensionless radial profile f(R) of an interface energy (:mod:`bcfem.radial_profile`)."""

    def shape(self, R): ...


class Enclosure(Protocol):
    """What encloses a fluid: its current volume as a form in the kinematics (:mod:`bcfem.physics.cavity`)."""

    def volume(self, kin) -> ufl.Form: ...


def total_energy(ctx, terms: Iterable) -> ufl.Form:
    """The sum of the terms' energies (one scalar form; discrete terms are not forms and are
    left out).

    Raises:
        ValueError: no term is a form.
    """
    energies = [t.energy(ctx) for t in terms if not isinstance(t, DiscreteTerm)]
    if not energies:
        raise ValueError("no energy: none of the terms is a form")
    total = energies[0]
    for energy in energies[1:]:
        total = total + energy
    return total
