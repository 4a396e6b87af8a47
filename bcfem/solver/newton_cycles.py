"""Stop a Newton solve whose iterates repeat.

With a variational inequality (contact bounds) full Newton steps can alternate between
two or three active sets for ever: the iterate and its residual norm come back. The
iteration map depends on the iterate alone within a solve, so such a solve would run to
``snes_max_it`` and fail; stopping it at the first repeat gives the same result
(DIVERGED_MAX_IT) without the remaining iterations.

A cycle returns close to an earlier iterate after steps that are not small; a solve that
creeps (steps shortened to keep a wall admissible) moves little at every step, and is
not a cycle: it may still arrive.
"""

from __future__ import annotations

from collections import deque

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

#: the cycle lengths looked for (1: a step of zero)
PERIODS = (1, 2, 3, 4)
#: an iterate repeats when its distance (max norm) to the one ``period`` back is at most this
#: times its last step (a step of zero: this times the iterate) ...
RETURN_RTOL = 1e-3
STALL_RTOL = 1e-14
#: ... and its residual norm has not fallen by more than this (relative) since then
NORM_RTOL = 1e-3


class RepeatedIterates:
    """A SNES monitor that ends the solve when an iterate returns to one of the last
    ``max(PERIODS)`` ones without a smaller residual (one reduction per iteration).

    Attributes:
        period: the cycle length that stopped the last solve (0: none).
        stopped: how many solves it stopped.
    """

    def __init__(self, snes: PETSc.SNES, comm):
        self.comm = comm
        self._history: deque = deque(maxlen=max(PERIODS))
        self.period = 0
        self.stopped = 0
        snes.setMonitor(self)

    def __call__(self, snes: PETSc.SNES, its: int, fnorm: float) -> None:
        if its == 0:
            self._history.clear()
            self.period = 0
        x = snes.getSolution().array_r
        if snes.getConvergedReason() == 0 and self._history:
            lags = list(reversed(self._history))  # lags[k]: the iterate k + 1 back
            norms = np.array([np.max(np.abs(x), initial=0.0)] +
                             [np.max(np.abs(x - old), initial=0.0) for old, _ in lags])
            self.comm.Allreduce(MPI.IN_PLACE, norms, op=MPI.MAX)
            scale, diffs = norms[0], norms[1:]
            step = diffs[0]
            for period, diff, (_, old_norm) in zip(PERIODS, diffs, lags):
                back = diff <= STALL_RTOL * scale if period == 1 else diff <= RETURN_RTOL * step
                if back and fnorm >= (1.0 - NORM_RTOL) * old_norm:
                    self.period = period
                    self.stopped += 1
                    snes.setConvergedReason(PETSc.SNES.ConvergedReason.DIVERGED_MAX_IT)
                    return
        self._history.append((x.copy(), fnorm))

