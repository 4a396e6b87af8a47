"""Volume control: step a volume constraint's target with the natural rows.

The counterpart of arc-length continuation when a volume, not the pressure,
is prescribed: the pressure stays the Lagrange multiplier of the constraint.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import ufl
from dolfinx import fem

from bcfem.mpi import global_sum
from bcfem.path.branch import ContinuationError


class VolumeControl:
    """Step a constraint's target with the natural rows.

    The problem must be built without a replacement row for the constraint's
    multiplier, so that its row is the constraint ``volume(u) = target``. A
    target is approached from the current state's volume in sub-steps: a failed
    sub-step is halved, a converged one lets the next grow, and nothing
    unconverged is ever kept.

    Args:
        volume: the constrained volume as a scalar form of the states.
        target: the run-time constant that the constraint's term holds the volume to.
        min_step: the smallest sub-step, relative to ``max(1, |target|)``.
    """

    def __init__(self, volume: ufl.Form, target: fem.Constant, min_step: float = 1e-10):
        self.target = target
        self._volume = fem.form(volume)
        self.min_step = min_step

    @classmethod
    def membrane(cls, ctx, min_step: float = 1e-10) -> VolumeControl:
        """The blister's: the volume enclosed by the membrane ``ctx.kin``, held by
        :class:`bcfem.physics.energies.PressureVolume` to its constant ``volume_target``."""
        return cls(ctx.kin.integral(ctx.kin.volume_density), ctx.constant("volume_target"), min_step)

    def volume(self) -> float:
        return global_sum(self._volume)

    def solve_to(self, problem, value: float) -> None:
        current = self.volume()
        step = value - current
        while True:
            trial = current + step
            if (step > 0 and trial > value) or (step < 0 and trial < value):
                trial = value
            self.target.value = np.asarray(trial)
            if problem.solve():
                current = trial
                if trial == value:
                    return
                step *= 1.5
            else:
                step *= 0.5
                if abs(step) < self.min_step * max(1.0, abs(value)):
                    raise ContinuationError(
                        f"volume control: no converged state beyond volume {current:.6g} towards "
                        f"{value:.6g} (last failure: {problem.failure})")

    def trace(self, problem, values, observe: Callable[[], dict]) -> list[dict]:
        rows = []
        for v in values:
            self.solve_to(problem, v)
            rows.append(observe())
        return rows
