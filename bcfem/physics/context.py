"""The context handed to every energy term: mesh, displacement, kinematics, states.

A term asks the context for what it needs. Global unknowns (a cavity pressure,
a debond radius, a load factor) are created on demand on dolfinx's real element
with :meth:`Context.real_state`; the problem builder later collects every state
the terms asked for. A state may live on another mesh than the displacement (a
field on a boundary submesh, :mod:`bcfem.kinematics.submesh`): the context then keeps the
entity map that relates that mesh to its own, for every form to compile with.
Run-time parameters are ``fem.Constant`` so forms compile once.
"""

from __future__ import annotations

import basix.ufl
import dolfinx
from dolfinx import fem


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
        self._real_space = None
        self._states: dict[str, fem.Function] = {"displacement": u}
        self._constants: dict[str, fem.Constant] = {}
        self._entity_maps: list = []

    @property
    def real_space(self) -> fem.FunctionSpace:
        if self._real_space is None:
            element = basix.ufl.real_element(self.mesh.basix_cell(), value_shape=(),
                                             dtype=dolfinx.default_real_type)
            self._real_space = fem.functionspace(self.mesh, element)
        return self._real_space

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
        """The run-time parameter ``name``; ``value`` is used only on creation."""
        if name not in self._constants:
            self._constants[name] = fem.Constant(self.mesh, dolfinx.default_scalar_type(value))
        return self._constants[name]

    @property
    def entity_maps(self) -> list:
        """The entity maps of the meshes of states on other meshes (empty if none)."""
        return list(self._entity_maps)

    @property
    def states(self) -> dict[str, fem.Function]:
        """All unknowns, displacement first, in creation order."""
        return dict(self._states)
