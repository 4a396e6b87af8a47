"""A scene's measures of the current state as objects, as FESTIM's derived quantities: each
has its column (:class:`bcfem.columns.Column`: name, unit, meaning) and a collective
:meth:`Observable.value`; a row of ``branch.csv`` is their values (:func:`row`), so the
columns a scene declares and the values it writes come from one list.

The shared ones: :class:`Integral` (a form over a scale: a cavity's volume over V0, an
energy), :class:`RealState` (a global unknown: a pressure, a debond radius) and
:class:`Measured` (any collective function: a point value, a cell maximum). Forms are
compiled when the observable is built, never per row.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import ufl
from dolfinx import fem

from bcfem.columns import SHARED, Column
from bcfem.mpi import global_sum, real_value


class Observable(ABC):
    """A measure of the current state with its column."""

    column: Column

    @property
    def name(self) -> str:
        return self.column.name

    @abstractmethod
    def value(self) -> float:
        """The measure of the current state (collective: every rank gets the same)."""


@dataclass
class Integral(Observable):
    """``form`` (compiled once) summed over the ranks, over ``scale``."""

    column: Column
    form: fem.Form
    scale: float = 1.0

    @classmethod
    def of(cls, column: Column | str, integrand: ufl.Form, scale: float = 1.0) -> Integral:
        return cls(_column(column), fem.form(integrand), scale)

    def value(self) -> float:
        return global_sum(self.form) / self.scale


@dataclass
class RealState(Observable):
    """A global unknown (a real-space state), over ``scale``."""

    column: Column
    state: fem.Function
    scale: float = 1.0

    def value(self) -> float:
        return real_value(self.state) / self.scale


@dataclass
class Measured(Observable):
    """Any collective measure (a point evaluation, a cell maximum)."""

    column: Column
    measure: Callable[[], float]

    def value(self) -> float:
        return float(self.measure())


def _column(column: Column | str) -> Column:
    return SHARED[column] if isinstance(column, str) else column


def cavity_volume(volume: ufl.Form, V0: float) -> Integral:
    """The shared ``V_over_V0``: a cavity's volume form (a membrane's ∫ volume density, a
    crater's enclosed volume) over its reference V0."""
    return Integral.of("V_over_V0", volume, V0)


def pressure(state: fem.Function, column: Column | str = "P") -> RealState:
    """A pressure unknown (``P`` of the blisters; ``p_over_pa`` of the craters)."""
    return RealState(_column(column), state)


def row(observables: Iterable[Observable]) -> dict:
    """The observables' values by column name (collective)."""
    return {o.name: o.value() for o in observables}
