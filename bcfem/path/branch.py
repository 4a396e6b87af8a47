"""The records of a traced branch, and the model changes a trace reacts to.

A :class:`Branch` holds the converged points of a path in order, its limit
points and events; a :class:`Switch` changes the model where a function of
the observables crosses zero; a :class:`ContinuationError` says where a path
stopped. These are plain data, shared by the continuation and its callers.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np


class ContinuationError(RuntimeError):
    """The continuation could not go on; the message says where and why.

    Attributes:
        branch: the converged part of the branch (empty until a trace fills it in).
        problem: the problem it was traced on, when a caller must close it.
    """

    def __init__(self, message: str = "", branch: Branch | None = None, problem=None):
        super().__init__(message)
        self.branch = branch if branch is not None else Branch()
        self.problem = problem


@dataclass
class LimitPoint:
    """A fold of the load parameter along the branch (dλ/ds = 0)."""

    kind: str  # "max" or "min" of the load parameter
    s: float
    values: dict


@dataclass
class Switch:
    """A change of the model along the path, such as delamination onset.

    When ``function(values)`` turns from negative to non-negative within a
    step, the crossing is located to ``event_tol``, recorded, and ``action()``
    is called there (e.g. it frees the debond radius); the path goes on from
    that point with the new equations.
    """

    name: str
    function: Callable[[dict], float]
    action: Callable[[], None]
    #: a state that must grow after the switch (e.g. the debond radius: no healing);
    #: the new tangent is turned to make it grow
    grows: str | None = None


@dataclass
class Branch:
    """Converged points, in order along the path, with their observables."""

    rows: list[dict] = field(default_factory=list)
    limit_points: list[LimitPoint] = field(default_factory=list)
    events: list[dict] = field(default_factory=list)
    newton_iterations: int = 0
    failed_steps: int = 0
    wall_time_s: float = 0.0

    def column(self, key: str) -> np.ndarray:
        return np.array([row[key] for row in self.rows])
