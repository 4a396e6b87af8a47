"""The context handed to every energy term: mesh, displacement, kinematics, states.

A term asks the context for what it needs. Global unknowns (a cavity pressure,
a debond radius, a load factor) are created on demand on dolfinx's real element
with :meth:`Context.real_state`; the problem builder later collects every state
the terms asked for. A state may live on another mesh than the displacement (a
field on a boundary submesh, :mod:`bcfem.kinematics.submesh`): the context then keeps the
entity map that relates that mesh to its own, for every form to compile with.
Every number a user or a sweep can change reaches UFL as a ``fem.Constant``, so a form
depends only on its structure and compiles once: a term's own parameters through
:meth:`Context.parameters` (two instances, two constants), a model's named controls (a volume
target, a suction ramp) through :meth:`Context.constant`.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from collections.abc import Callable
from typing import Any

import basix.ufl
import dolfinx
import numpy as np
import ufl
from dolfinx import fem

from bcfem.mpi import global_sum


def _is_parameter(field: dataclasses.Field, value) -> bool:
    """A field declared ``float`` with a finite value is a run-time parameter; a non-finite
    one (a Gent limit ``Jm = inf``) selects another form, so it stays a number."""
    return (field.type in ("float", float) and isinstance(value, (int, float)) and not isinstance(value, bool)
            and math.isfinite(value))


class Context:
    """States and shared objects of one model.

    Args:
        u: the displacement field (the first state).
        kinematics: the kinematics object of the model (e.g. AxisymmetricMembrane);
            may be set later as ``ctx.kin`` when it depends on a state of the
            context (a moving edge radius).
    """

    def __init__(self, u: fem.Function, kinematics=None):
        self.u = u
        self.kin = kinematics
        self.mesh = u.function_space.mesh
        self._real_space: fem.FunctionSpace | None = None
        self._states: dict[str, fem.Function] = {"displacement": u}
        self._constants: dict[str, fem.Constant] = {}
        # id(owner) -> (owner, its copy with constants): the owner is kept so its id stays its own
        self._owned: dict[int, tuple[Any, Any]] = {}
        self._named: dict[str, list[fem.Constant]] = {}
        self._entity_maps: list = []
        #: the body's measure, shared with every view (:meth:`with_kinematics`)
        self._measure: list[fem.Constant] = []
        #: what terms compute once per context (a compiled measure of the state)
        self._cache: dict[str, Any] = {}

    @property
    def real_space(self) -> fem.FunctionSpace:
        if self._real_space is None:
            element = basix.ufl.real_element(self.mesh.basix_cell(), value_shape=(),
                                             dtype=dolfinx.default_real_type)
            self._real_space = fem.functionspace(self.mesh, element)
        return self._real_space

    def body_measure(self) -> fem.Constant:
        """The body's measure ∫ 1 dx over :attr:`mesh`, a constant (collective; assembled on
        the first request, a property of the mesh like :attr:`real_space`)."""
        if not self._measure:
            measure = global_sum(fem.form(1.0 * ufl.dx(domain=self.mesh)))
            self._measure.append(fem.Constant(self.mesh, dolfinx.default_scalar_type(measure)))
        return self._measure[0]

    def cached(self, key: str, make: Callable[[], Any]) -> Any:
        """``make()`` once per context (and kinematics): a term's compiled measure of the state."""
        key = f"{key}@{id(self.kin)}"
        if key not in self._cache:
            self._cache[key] = make()
        return self._cache[key]

    def with_kinematics(self, kin) -> Context:
        """This context seen through another kinematics (a membrane on a solid's surface): the
        same states, constants and parameters, ``kin`` replaced."""
        self.real_space  # one real space for both: created here, before the view copies it
        view = copy.copy(self)  # shallow: the states' and constants' dicts are shared
        view.kin = kin
        return view

    def real_state(self, name: str) -> fem.Function:
        """The global scalar unknown ``name``, created on first request."""
        if name not in self._states:
            self._states[name] = fem.Function(self.real_space, name=name)
        return self._states[name]

    def field_state(self, name: str, degree: int = 1) -> fem.Function:
        """A scalar Lagrange field unknown ``name`` (e.g. the mixed pressure of a
        nearly incompressible solid), created on first request; degree 0 is one constant
        per cell (discontinuous)."""
        if name not in self._states:
            space = fem.functionspace(self.mesh, ("Lagrange", degree) if degree > 0 else ("DG", 0))
            self._states[name] = fem.Function(space, name=name)
        return self._states[name]

    def state_in(self, name: str, space: fem.FunctionSpace, entity_map=None) -> fem.Function:
        """The unknown ``name`` in ``space``, created on first request. A space on another
        mesh needs the ``entity_map`` (``dolfinx.mesh.EntityMap``) relating that mesh to
        :attr:`mesh`; forms are integrated over :attr:`mesh`."""
        if name not in self._states:
            if space.mesh is not self.mesh:
                if entity_map is None:
                    raise ValueError(f"state {name!r} lives on another mesh: give its entity map")
                if all(m is not entity_map for m in self._entity_maps):
                    self._entity_maps.append(entity_map)
            self._states[name] = fem.Function(space, name=name)
        return self._states[name]

    def constant(self, name: str, value: float = 0.0) -> fem.Constant:
        """The model's run-time control ``name`` (a volume target, a suction ramp), shared by
        every term and path that asks for it by name; ``value`` is used only on creation.
        A term's own parameter is :meth:`parameters`'s instead.

        Raises:
            ValueError: ``name`` names term parameters (set them with :meth:`set`).
        """
        if name in self._named:
            raise ValueError(f"{name!r} names a term's parameter: set it with ctx.set({name!r}, value)")
        if name not in self._constants:
            self._constants[name] = fem.Constant(self.mesh, dolfinx.default_scalar_type(value))
        return self._constants[name]

    def parameters[T](self, owner: T, names: dict[str, str] | None = None) -> T:
        """``owner`` (a frozen dataclass: a term, a material) as its forms see it: a copy whose
        fields declared ``float`` are ``fem.Constant`` s of this instance. Changing a value then
        never recompiles a form; two instances of one class are two sets of constants, whatever
        their values. The same instance gets the same constants on every request (every stage,
        every derived context). A term asks for a part's parameters itself
        (``ctx.parameters(self.material)``).

        Args:
            owner: the instance whose parameters these are.
            names: field -> a name by which :meth:`set` and :meth:`value` reach the field's
                constant (several terms may share a name: a ramp of every γl).
        """
        key = id(owner)
        if key not in self._owned:
            self._owned[key] = (owner, self._with_constants(owner))
            for field, name in (names or {}).items():
                self._named.setdefault(name, []).append(getattr(self._owned[key][1], field))
        return self._owned[key][1]

    def parameter(self, owner, field: str) -> fem.Constant:
        """The constant of ``owner``'s field ``field`` (:meth:`parameters`)."""
        constant = getattr(self.parameters(owner), field)
        if not isinstance(constant, fem.Constant):
            raise ValueError(f"{type(owner).__name__}.{field} is not a run-time parameter (a finite float field)")
        return constant

    def _with_constants(self, owner):
        copied = copy.copy(owner)  # no __init__: the copy's checks ran on the owner
        for field in dataclasses.fields(owner):
            value = getattr(owner, field.name)
            if _is_parameter(field, value):
                object.__setattr__(copied, field.name, fem.Constant(self.mesh, dolfinx.default_scalar_type(value)))
        return copied

    def set(self, name: str, value: float) -> None:
        """Set every constant named ``name``: the control, or the term parameters so named.

        Raises:
            KeyError: no constant is named so.
        """
        found = self._named.get(name, []) + ([self._constants[name]] if name in self._constants else [])
        if not found:
            raise KeyError(f"no run-time constant is named {name!r} (named: {sorted(self.names)})")
        for constant in found:
            constant.value = np.asarray(value)

    def value(self, name: str) -> float:
        """The value of the constants named ``name`` (:meth:`set`)."""
        found = self._named.get(name) or [self.constant(name)]
        return float(found[0].value)

    @property
    def names(self) -> frozenset[str]:
        """The names :meth:`set` knows."""
        return frozenset(self._named) | frozenset(self._constants)

    @property
    def entity_maps(self) -> list:
        """The entity maps of the meshes of states on other meshes (empty if none)."""
        return list(self._entity_maps)

    @property
    def states(self) -> dict[str, fem.Function]:
        """All unknowns, displacement first, in creation order."""
        return dict(self._states)
