"""What ends a path or a stage, as objects (as PyBaMM's experiment steps end on termination
objects).

A :class:`Termination` measures a row of observables; the end is where the measure turns
non-negative, so a path stops at the first row past it and a root finder or a bisection
locates it between the last row before and that one. A termination is a callable, so it
goes wherever a path takes an end function (:class:`bcfem.run.scene.BranchScene` ``end``),
and its words are what the summary reports (``stages``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass


class Termination(ABC):
    """An end condition on a row of observables."""

    @abstractmethod
    def measure(self, row: dict) -> float:
        """>= 0 where the path ends (a continuous measure, for root finders)."""

    @abstractmethod
    def __str__(self) -> str:
        """The condition in words (the summary's ``stages``)."""

    def reached(self, row: dict) -> bool:
        return self.measure(row) >= 0

    def __call__(self, row: dict) -> float:
        return self.measure(row)


@dataclass(frozen=True)
class Reaches(Termination):
    """The column ``column`` reaches ``target`` (rising, or falling with ``falling``)."""

    column: str
    target: float
    falling: bool = False

    def measure(self, row: dict) -> float:
        value = row[self.column]
        return self.target - value if self.falling else value - self.target

    def __str__(self) -> str:
        return f"{self.column} {'falls' if self.falling else 'rises'} to {self.target:g}"


@dataclass(frozen=True)
class AnyOf(Termination):
    """The first of several ends."""

    ends: tuple[Termination, ...]

    def measure(self, row: dict) -> float:
        return max(end.measure(row) for end in self.ends)

    def __str__(self) -> str:
        return ", or ".join(map(str, self.ends))


@dataclass(frozen=True)
class Described(Termination):
    """An end that is not a condition on one row (after one solve, a located root of a
    scene's own measure): words only; it is never reached by a row."""

    words: str

    def measure(self, row: dict) -> float:
        return -1.0

    def __str__(self) -> str:
        return self.words


#: the platen force vanishes (an unloading platen: compressive < 0)
PLATEN_FORCE_ZERO = Reaches("platen_force", 0.0)
