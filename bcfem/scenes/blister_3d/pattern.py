r"""Adhesion that varies over the substrate, Δγ(x, y), for ``blister-3d --edge adhesive``
(the dissertation's eq. 10.1), and its wetting term.

``--delta-gamma`` takes a number or a pattern (values over μ_f t0, lengths over R0):

* ``stripes:PERIOD:LOW:HIGH``: Δγ = (LOW + HIGH)/2 − (HIGH − LOW)/2 cos(2π x/PERIOD), stripes
  along y, LOW on the centre line x = 0;
* a radial profile of the distance from the centroid, as ``blister-rigid --adhesion`` and
  ``blister-soft --delta-gamma`` take it (:mod:`bcfem.radial_profile`: ``step:R_s:inner:outer``,
  a disc; ``ramp:...``; ``table:FILE``), so that a circle meets the axisymmetric scenes;
* ``map:FILE``: Δγ over the plane, rows ``x y value`` on a rectangular grid, in the scene's
  frame (lengths over R0 from the outline's centroid), interpolated bilinearly
  (:class:`Map`, :class:`MappedWetting`).

Δγ belongs to the substrate: the liquid wets the substrate inside the front at the cost
γ_ls − Δγ(x) per area (:class:`PatternedWetting`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from bcfem.physics.protocols import Term
from bcfem.radial_profile import RadialProfile, read_rows
from bcfem.radial_profile import parse as parse_profile


@dataclass(frozen=True)
class Pattern:
    """Stripes of Δγ (the module's docstring).

    Attributes:
        text: the flag's text.
        period: the stripes' period.
        values: (LOW, HIGH).
    """

    text: str
    period: float
    values: tuple

    def __str__(self) -> str:
        return self.text

    def _blend(self, x, cos):
        low, high = self.values
        return 0.5 * (low + high) - 0.5 * (high - low) * cos(2 * math.pi * x / self.period)

    def expression(self, x, y):
        """Δγ at the point (x, y), a UFL expression."""
        import ufl  # here: the parameters read patterns without the finite-element stack

        return self._blend(x, ufl.cos)

    def at(self, points: np.ndarray) -> np.ndarray:
        """Δγ at the rows (x, y) of ``points``."""
        return self._blend(points[:, 0], np.cos)


@dataclass(frozen=True, eq=False)
class Map:
    """Δγ on a rectangular grid of the plane, bilinear between its nodes (``map:FILE``; the
    file is read on creation, and only the text is a field, for the run's ``parameters``).

    Attributes:
        text: the flag's text, ``map:FILE``.
        x, y: the grid's coordinates, increasing.
        table: Δγ at (x[i], y[j]) as ``table[i, j]``.
    """

    text: str
    if TYPE_CHECKING:  # set from the file, not fields (``parameters`` records the text)
        x: np.ndarray = field(init=False)
        y: np.ndarray = field(init=False)
        table: np.ndarray = field(init=False)

    def __post_init__(self):
        for name, value in zip(("x", "y", "table"), _read_grid(self.text.split(":", 1)[1])):
            object.__setattr__(self, name, value)

    def __str__(self) -> str:
        return self.text

    @property
    def values(self) -> tuple:
        return (float(self.table.min()), float(self.table.max()))

    def covers(self, points: np.ndarray) -> bool:
        """Whether every row (x, y) of ``points`` lies on the grid (its closed rectangle)."""
        return bool(np.all((points[:, 0] >= self.x[0]) & (points[:, 0] <= self.x[-1])
                           & (points[:, 1] >= self.y[0]) & (points[:, 1] <= self.y[-1])))

    def at(self, points: np.ndarray) -> np.ndarray:
        """Δγ at the rows (x, y) of ``points`` (ValueError for a point off the grid)."""
        points = np.asarray(points, dtype=float)[:, :2]
        if not self.covers(points):
            outside = points[np.argmax(np.maximum.reduce([self.x[0] - points[:, 0], points[:, 0] - self.x[-1],
                                                          self.y[0] - points[:, 1], points[:, 1] - self.y[-1]]))]
            raise ValueError(f"--delta-gamma {self.text}: the point ({outside[0]:.4g}, {outside[1]:.4g}) lies off "
                             f"the map [{self.x[0]:g}, {self.x[-1]:g}] x [{self.y[0]:g}, {self.y[-1]:g}]")
        i = np.clip(np.searchsorted(self.x, points[:, 0], side="right") - 1, 0, len(self.x) - 2)
        j = np.clip(np.searchsorted(self.y, points[:, 1], side="right") - 1, 0, len(self.y) - 2)
        s = (points[:, 0] - self.x[i]) / (self.x[i + 1] - self.x[i])
        t = (points[:, 1] - self.y[j]) / (self.y[j + 1] - self.y[j])
        T = self.table
        return ((1 - s) * (1 - t) * T[i, j] + s * (1 - t) * T[i + 1, j]
                + (1 - s) * t * T[i, j + 1] + s * t * T[i + 1, j + 1])


def _read_grid(path: str) -> tuple:
    """(x, y, table) from rows ``x y value`` (whitespace or commas, ``#`` comments) that fill a
    rectangular grid of at least 2 x 2 nodes, each node once (ValueError naming the file and line)."""
    rows = read_rows(Path(path), "x y value", "map")
    data = np.array(rows).reshape(-1, 3)
    x, y = np.unique(data[:, 0]), np.unique(data[:, 1])
    if len(x) < 2 or len(y) < 2 or len(data) != len(x) * len(y):
        raise ValueError(f"the map {path!r} must fill a rectangular grid of at least 2 x 2 nodes, each node "
                         f"once (got {len(data)} rows on {len(x)} x {len(y)} coordinates)")
    table = np.full((len(x), len(y)), np.nan)
    table[np.searchsorted(x, data[:, 0]), np.searchsorted(y, data[:, 1])] = data[:, 2]
    if np.isnan(table).any():
        raise ValueError(f"the map {path!r} names a node twice and leaves another out")
    return x, y, table


def parse(text: str) -> float | Pattern | RadialProfile | Map:
    """A number, stripes, a map or a radial profile (ValueError naming the forms)."""
    if text.startswith("map:"):
        return Map(text)
    if not text.startswith("stripes"):
        return parse_profile(text)
    fields = text.split(":")[1:]
    form = "stripes:PERIOD:LOW:HIGH"
    try:
        numbers = [float(f) for f in fields]
    except ValueError:
        raise ValueError(f"{form} takes numbers (got {text!r})") from None
    if len(numbers) != 3 or not all(map(math.isfinite, numbers)) or numbers[0] <= 0:
        raise ValueError(f"expected {form} with a finite PERIOD > 0 (got {text!r})")
    return Pattern(text, numbers[0], tuple(numbers[1:]))


def varies(value) -> bool:
    """Whether Δγ is a pattern, a map or a profile (not a number)."""
    return isinstance(value, Pattern | RadialProfile | Map)


def values_of(value) -> tuple:
    """The Δγ values a number, stripes or a profile takes (their range bounds the cost)."""
    return value.values if varies(value) else (value,)


def expression(value, x, y):
    """Δγ at (x, y), a UFL expression."""
    if isinstance(value, Pattern):
        return value.expression(x, y)
    import ufl

    return value.ufl(ufl.sqrt(x * x + y * y))


def at(value, points: np.ndarray) -> np.ndarray:
    """Δγ at the rows (x, y) of ``points``."""
    if isinstance(value, Pattern | Map):
        return value.at(points)
    return value(np.hypot(points[:, 0], points[:, 1]))


@dataclass(frozen=True)
class PatternedWetting(Term):
    r"""The wetted substrate's energy with a patterned adhesion,
    :math:`\int_\Omega \gamma_{ls} - \Delta\gamma(X)\, dA`, over the debonded region Ω of
    the reference plane (the mesh, which grows with the front). The film is clamped, unmoved,
    on the front, so Ω is the wetted substrate and this is ``WettedSubstrate``'s energy: it does
    not depend on the displacement, and its coordinate derivative is the cost at the front.
    (Written on the current positions, ∫ (γ_ls − Δγ(x)) n_z dA, it is the same in exact
    arithmetic, but where the membrane overhangs the front, quadrature of a varying Δγ over the
    fold leaves a node-to-node noise in the release rate.) γ_ls is the run-time constant
    ``gamma_ls``.

    Attributes:
        gamma_ls: γ_ls over μ_f t0.
        delta_gamma: a :class:`Pattern` or a :class:`bcfem.radial_profile.RadialProfile`.
    """

    gamma_ls: float
    delta_gamma: object
    name = "patterned_wetting"
    multipliers = ()

    def energy(self, ctx):
        kin = ctx.kin
        X = kin.x - kin.u  # the reference point: the substrate's under the clamped front
        gamma_ls = ctx.parameters(self, {"gamma_ls": "gamma_ls"}).gamma_ls
        return kin.integral(gamma_ls - expression(self.delta_gamma, X[0], X[1]))


@dataclass
class MappedWetting(Term):
    r""":class:`PatternedWetting` for a :class:`Map`, which UFL cannot evaluate at a point:
    Δγ is its interpolant Δγ_h on the current mesh, and the energy

    .. math:: \int_\Omega \gamma_{ls} - \Delta\gamma_h - \nabla\Delta\gamma_h\cdot(X - X_h)\, dA,

    with X_h the interpolant of the coordinates (X − X_h = 0), has the value of the wetted
    substrate's energy and the coordinate derivative of a Δγ fixed to the substrate,
    ∮ (γ_ls − Δγ_h) θ·ν ds: the last term undoes the convection of Δγ_h with the mesh.
    :meth:`refresh` interpolates both anew after the mesh moves.

    Attributes:
        gamma_ls: γ_ls over μ_f t0.
        delta_gamma: the :class:`Map`.
    """

    gamma_ls: float
    delta_gamma: Map
    name = "patterned_wetting"
    multipliers = ()

    def __post_init__(self):
        self._fields: tuple = ()

    def energy(self, ctx):
        import ufl
        from dolfinx import fem

        kin = ctx.kin
        if not self._fields:
            degree = ctx.mesh.geometry.cmaps[0].degree
            self._fields = (fem.Function(fem.functionspace(ctx.mesh, ("Lagrange", degree))),
                            fem.Function(fem.functionspace(ctx.mesh, ("Lagrange", degree, (2,)))))
            self.refresh()
        dgamma, nodes = self._fields
        X = kin.x - kin.u
        here = dgamma + ufl.dot(ufl.grad(dgamma), ufl.as_vector([X[0], X[1]]) - nodes)
        return kin.integral(ctx.parameters(self, {"gamma_ls": "gamma_ls"}).gamma_ls - here)

    def refresh(self) -> None:
        """Δγ_h and X_h at the mesh's current nodes (ValueError if a node is off the map)."""
        dgamma, nodes = self._fields
        dgamma.interpolate(lambda x: self.delta_gamma.at(x[:2].T))
        nodes.interpolate(lambda x: x[:2].copy())
