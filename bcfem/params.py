"""Solver and continuation parameters: frozen, validated dataclasses."""

from __future__ import annotations

import math
from dataclasses import dataclass


def require(condition: bool, message: str) -> None:
    """Raise ``ValueError(message)`` unless ``condition``; messages name the parameter and range."""
    if not condition:
        raise ValueError(message)


@dataclass(frozen=True)
class ContinuationParams:
    """Pseudo-arc-length step control.

    The arc length is measured in a mesh-independent norm, the mean over the
    reference body of the squared states that measure it plus the squared load,
    each over its typical size (:class:`bcfem.continuation.ArcLength`), so the
    same steps work on every mesh.

    Attributes:
        ds: first step.
        ds_min: smallest step before the continuation gives up.
        ds_max: largest step while |load| <= load_scale; beyond, it grows with |load|/load_scale.
        target_iterations: Newton iterations per step that the step control aims at.
        max_steps: hard limit on accepted steps.
        event_tol: tolerance, in arc length, to which limit points and end points are located.
        max_correction: a corrected point farther than this times the step from its predictor
            is rejected like a failed solve (the step is halved): Newton jumped to another
            branch. A smooth branch corrects by O(ds^2) and a kink (a contact's active set)
            by ds sin(angle), so 1 passes both; inf: no check.
    """

    ds: float = 0.05
    ds_min: float = 1e-7
    ds_max: float = 0.5
    target_iterations: int = 4
    max_steps: int = 2000
    event_tol: float = 1e-11
    max_correction: float = math.inf

    def __post_init__(self):
        require(0 < self.ds_min <= self.ds <= self.ds_max and math.isfinite(self.ds_max),
                f"need 0 < ds_min <= ds <= ds_max < inf (got {self.ds_min}, {self.ds}, {self.ds_max})")
        require(self.target_iterations >= 1, f"target_iterations must be >= 1 (got {self.target_iterations})")
        require(self.max_steps >= 1, f"max_steps must be >= 1 (got {self.max_steps})")
        require(self.event_tol > 0, f"event_tol must be > 0 (got {self.event_tol})")
        require(self.max_correction > 0, f"max_correction must be > 0 (got {self.max_correction})")
